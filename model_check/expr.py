"""The expression language shared by our checker and SPIN.

Guards, effects and properties are written as Python-syntax strings over the
model's variable names and parsed with `ast`, so one text yields both the
Python the checker runs and the Promela SPIN runs: the two cannot drift apart.
Only integer arithmetic, comparisons, and/or/not, `a if c else b` and
min/max are allowed; anything else is rejected with the offending text.
"""
from __future__ import annotations

import ast
from typing import Callable, Iterable

_PY_BIN = {ast.Add: "+", ast.Sub: "-", ast.Mult: "*", ast.FloorDiv: "//", ast.Mod: "%"}
_PML_BIN = {ast.Add: "+", ast.Sub: "-", ast.Mult: "*", ast.FloorDiv: "/", ast.Mod: "%"}
_CMP = {ast.Eq: "==", ast.NotEq: "!=", ast.Lt: "<", ast.LtE: "<=", ast.Gt: ">", ast.GtE: ">="}


class ExprError(ValueError):
    """An expression outside the shared language (a model-building bug, not a user error)."""


def parse(text: str) -> ast.expr:
    try:
        tree = ast.parse(text, mode="eval")
    except SyntaxError as exc:
        raise ExprError(f"bad expression {text!r}: {exc.msg}") from None
    _check(tree.body, text)
    return tree.body


def _is_bool(node: ast.expr) -> bool:
    return (isinstance(node, (ast.Compare, ast.BoolOp))
            or (isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.Not))
            or (isinstance(node, ast.Constant) and isinstance(node.value, bool)))


def _check(node: ast.expr, text: str) -> None:
    if isinstance(node, ast.BoolOp):
        for v in node.values:
            if not _is_bool(v):
                # Python's `and` returns an operand, Promela's && returns 0/1: keep them equal.
                raise ExprError(f"operands of and/or must be comparisons in {text!r}")
            _check(v, text)
    elif isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.Not, ast.USub)):
        _check(node.operand, text)
    elif isinstance(node, ast.BinOp) and type(node.op) in _PY_BIN:
        _check(node.left, text)
        _check(node.right, text)
    elif isinstance(node, ast.Compare) and len(node.ops) == 1 and type(node.ops[0]) in _CMP:
        _check(node.left, text)
        _check(node.comparators[0], text)
    elif isinstance(node, ast.IfExp):
        for part in (node.test, node.body, node.orelse):
            _check(part, text)
    elif isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id in ("min", "max") \
            and len(node.args) == 2 and not node.keywords:
        for a in node.args:
            _check(a, text)
    elif isinstance(node, ast.Name):
        pass
    elif isinstance(node, ast.Constant) and isinstance(node.value, (int, bool)):
        pass
    else:
        raise ExprError(f"unsupported construct {ast.dump(node)[:40]} in {text!r}")


def names(text: str) -> set[str]:
    return {n.id for n in ast.walk(parse(text)) if isinstance(n, ast.Name) and n.id not in ("min", "max")}


def to_python(text: str, rename: Callable[[str], str]) -> str:
    return _emit(parse(text), rename, python=True)


def to_promela(text: str, rename: Callable[[str], str] = lambda n: n) -> str:
    return _emit(parse(text), rename, python=False)


def _emit(node: ast.expr, rename: Callable[[str], str], python: bool) -> str:
    def e(n: ast.expr) -> str:
        return _emit(n, rename, python)

    if isinstance(node, ast.Name):
        return rename(node.id)
    if isinstance(node, ast.Constant):
        return str(int(node.value))
    if isinstance(node, ast.BoolOp):
        op = (" and " if python else " && ") if isinstance(node.op, ast.And) else (" or " if python else " || ")
        return "(" + op.join(e(v) for v in node.values) + ")"
    if isinstance(node, ast.UnaryOp):
        if isinstance(node.op, ast.Not):
            return f"(not {e(node.operand)})" if python else f"(!{e(node.operand)})"
        return f"(-{e(node.operand)})"
    if isinstance(node, ast.BinOp):
        table = _PY_BIN if python else _PML_BIN
        return f"({e(node.left)} {table[type(node.op)]} {e(node.right)})"
    if isinstance(node, ast.Compare):
        return f"({e(node.left)} {_CMP[type(node.ops[0])]} {e(node.comparators[0])})"
    if isinstance(node, ast.IfExp):
        if python:
            return f"({e(node.body)} if {e(node.test)} else {e(node.orelse)})"
        return f"({e(node.test)} -> {e(node.body)} : {e(node.orelse)})"
    if isinstance(node, ast.Call):
        a, b = (e(x) for x in node.args)
        cmp = "<" if node.func.id == "min" else ">"  # type: ignore[attr-defined]
        if python:   # a conditional is cheaper than calling the builtin on CPython
            return f"({a} if {a} {cmp} {b} else {b})"
        return f"(({a} {cmp} {b}) -> {a} : {b})"
    raise ExprError(f"cannot emit {ast.dump(node)[:40]}")


def any_of(parts: Iterable[str]) -> str:
    parts = [f"({p})" for p in parts]
    return " or ".join(parts) if parts else "False"


def all_of(parts: Iterable[str]) -> str:
    parts = [f"({p})" for p in parts]
    return " and ".join(parts) if parts else "True"


def count_of(parts: Iterable[str]) -> str:
    """Number of true conditions; comparisons are 0/1 in Python and Promela alike."""
    parts = [f"({p})" for p in parts]
    return " + ".join(parts) if parts else "0"


def interval(text: str, ranges: dict[str, tuple[int, int]]) -> tuple[int, int] | None:
    """Bounds of an expression's value given the variables' ranges (None: unknown)."""
    return _iv(parse(text), ranges)


def _iv(node: ast.expr, r: dict[str, tuple[int, int]]) -> tuple[int, int] | None:
    if isinstance(node, ast.Constant):
        return int(node.value), int(node.value)
    if isinstance(node, ast.Name):
        return r.get(node.id)
    if isinstance(node, (ast.Compare, ast.BoolOp)) or (isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.Not)):
        return 0, 1
    if isinstance(node, ast.IfExp):
        a, b = _iv(node.body, r), _iv(node.orelse, r)
        return None if a is None or b is None else (min(a[0], b[0]), max(a[1], b[1]))
    if isinstance(node, ast.Call):
        a, b = (_iv(x, r) for x in node.args)
        if a is None or b is None:
            return None
        f = min if node.func.id == "min" else max  # type: ignore[attr-defined]
        return f(a[0], b[0]), f(a[1], b[1])
    if isinstance(node, ast.BinOp) and isinstance(node.op, (ast.Add, ast.Sub)):
        a, b = _iv(node.left, r), _iv(node.right, r)
        if a is None or b is None:
            return None
        return (a[0] + b[0], a[1] + b[1]) if isinstance(node.op, ast.Add) else (a[0] - b[1], a[1] - b[0])
    return None
