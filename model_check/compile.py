"""Compile a guarded-command model into specialised Python for the checker.

Speed is the point (issue 3 asks >= 250,000 states/s and within 4x of SPIN on
CPython): a state is one int with every variable in a fixed bit field. The
generated `expand` explores one breadth-first layer; by default it is the
optimised one from `fastgen` (decision tree over the guards, fields read in
place, memoised invariants and effects). The plain version below -- unpack
every field into locals, evaluate every guard inline, build each successor by
adding `(new - old) << shift` per assigned field -- is kept as the reference
the tests hold the optimised one to, and `successors`/predicates (traces,
liveness) still use that plain scheme.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

from model_check import expr, fastgen, native
from model_check.gcl import Model


class RangeError(Exception):
    """An effect produced a value outside its variable's range (a model bug)."""


@dataclass
class Layout:
    shift: dict[str, int]
    width: dict[str, int]
    total_bits: int

    def pack(self, values: dict[str, int]) -> int:
        s = 0
        for name, sh in self.shift.items():
            s |= values[name] << sh
        return s

    def unpack(self, s: int) -> dict[str, int]:
        return {n: (s >> sh) & ((1 << self.width[n]) - 1) for n, sh in self.shift.items()}

def layout_of(model: Model) -> Layout:
    shift, width, pos = {}, {}, 0
    for v in model.vars:
        shift[v.name], width[v.name] = pos, v.bits
        pos += v.bits
    return Layout(shift, width, pos)

class _NoNative:
    """The reference path's stand-in for native.Builder: no compiled model."""

    def __call__(self) -> None:
        return None

    def cached(self) -> bool:
        return False


@dataclass
class Compiled:
    """The generated functions and the source they came from (kept for debugging)."""

    layout: Layout
    init: int                   # canonical initial state
    init_raw: int               # the model's initial state as written
    expand: Callable            # (frontier, seen, cov) -> (next, None) | (next, (kind, index, state))
    successors: Callable        # state -> [(rule_index, raw successor)]
    canon: Callable[[int], int]
    predicates: dict[str, Callable[[int], bool]]
    source: str
    edges: Callable | None = None   # (frontier, nxt, rules, ends) -> hit: one layer's edges (storage)
    native: Callable[[], native.Native | None] = field(default_factory=_NoNative)   # the C successor function, built on first call
    # (a native.Builder: also says with `cached()` whether building it costs a compiler run)

def _unpack_lines(model: Model, lay: Layout, indent: str, src: str = "s") -> list[str]:
    return _var_lines(model, lay, indent, src) + [
        f"{indent}v_{name} = {expr.to_python(text, lambda n: 'v_' + n)}" for name, text in model.defs]

def _var_lines(model: Model, lay: Layout, indent: str, src: str = "s") -> list[str]:
    return [f"{indent}v_{v.name} = ({src} >> {lay.shift[v.name]}) & {(1 << lay.width[v.name]) - 1}"
            if lay.shift[v.name] else f"{indent}v_{v.name} = {src} & {(1 << lay.width[v.name]) - 1}"
            for v in model.vars]

def _effect_lines(model: Model, lay: Layout, rule, indent: str) -> tuple[list[str], str]:
    """Statements computing the rule's new values and the expression of the packed successor."""
    current = {v.name: f"v_{v.name}" for v in model.vars}
    lines: list[str] = []
    for k, (target, value) in enumerate(rule.effect):
        local = f"n{k}_{target}"
        py = expr.to_python(value, lambda n: current[n])
        lines.append(f"{indent}{local} = {py}")
        hi = model.var(target).hi
        iv = expr.interval(value, {v.name: (0, v.hi) for v in model.vars})
        if iv is not None and 0 <= iv[0] and iv[1] <= hi:
            pass                      # provably in range: no run-time check needed
        elif not value.strip().isdigit():
            lines.append(f"{indent}if not 0 <= {local} <= {hi}: raise RangeError("
                         f"'{rule.name}: {target} = ' + str({local}))")
        elif not 0 <= int(value) <= model.var(target).hi:
            raise expr.ExprError(f"{rule.name}: constant {value} outside {target}'s range")
        current[target] = local
    changed = [n for n in current if current[n] != f"v_{n}"]
    parts = ["s"] + [f"(({current[n]} - v_{n}) << {lay.shift[n]})" if lay.shift[n] else f"({current[n]} - v_{n})"
                     for n in changed]
    return lines, " + ".join(parts)

def _canon_source(model: Model, lay: Layout) -> list[str]:
    out = ["def canon(s):"]
    if not model.symmetry:
        out.append("    return s")
        return out
    for g in model.symmetry:
        starts = [lay.shift[b[0]] for b in g.blocks]
        width = sum(lay.width[n] for n in g.blocks[0])
        for b in g.blocks:
            pos = lay.shift[b[0]]
            for n in b:
                if lay.shift[n] != pos:
                    raise expr.ExprError(f"symmetry block {b} of {g.name} is not contiguous")
                pos += lay.width[n]
        m = (1 << width) - 1
        clear = 0
        for st in starts:
            clear |= m << st
        vals = ", ".join(f"(s >> {st}) & {m}" for st in starts)
        out.append(f"    w = sorted(({vals},))")
        rebuild = " | ".join(f"(w[{i}] << {st})" for i, st in enumerate(starts))
        out.append(f"    s = (s & ~{clear}) | {rebuild}")
    out.append("    return s")
    return out

def compile_model(model: Model, optimise: bool = True) -> Compiled:
    """`optimise=False` generates the plain reference `expand` (the tests compare the two)."""
    lay = layout_of(model)
    sym = bool(model.symmetry)
    src: list[str] = []
    src += _canon_source(model, lay)
    # -- expand: one breadth-first layer ---------------------------------------
    def layer_source(edges: bool) -> list[str]:
        if optimise:
            return fastgen.expand_source(model, lay.shift, lay.width, lay.total_bits, edges,
                                         "edges" if edges else "expand")
        return _reference_expand(model, lay, sym, edges)

    src += layer_source(False)
    # -- successors of one state (counterexamples, liveness) -------------------
    src.append("def successors(s):")
    src.append("    out = []")
    src += _unpack_lines(model, lay, "    ")
    for i, rule in enumerate(model.rules):
        src.append(f"    if {expr.to_python(rule.guard, lambda n: 'v_' + n)}:")
        lines, packed = _effect_lines(model, lay, rule, "        ")
        src += lines
        src.append(f"        out.append(({i}, {packed}))")
    src.append("    return out")
    # -- edges: one layer, every edge recorded (the engine's search, see storage) ----
    src += layer_source(True)
    # -- predicates ---------------------------------------------------------------
    preds: dict[str, str] = {"final": model.final}
    for i, inv in enumerate(model.invariants):
        preds[f"inv{i}"] = inv.expr
    for i, r in enumerate(model.responses):
        preds[f"trigger{i}"] = r.trigger
        preds[f"goal{i}"] = r.goal
    for key, text in preds.items():
        src.append(f"def pred_{key}(s):")
        src += _unpack_lines(model, lay, "    ")
        src.append(f"    return bool({expr.to_python(text, lambda n: 'v_' + n)})")
    source = "\n".join(src) + "\n"
    namespace: dict = {"RangeError": RangeError}
    exec(compile(source, f"<model {model.name}>", "exec"), namespace)
    init = lay.pack(model.initial)
    return Compiled(layout=lay, init=namespace["canon"](init), init_raw=init, expand=namespace["expand"],
                    successors=namespace["successors"], canon=namespace["canon"],
                    predicates={k: namespace[f"pred_{k}"] for k in preds}, source=source,
                    edges=namespace["edges"],
                    native=native.Builder(model, lay.shift, lay.width, lay.total_bits) if optimise
                    else _NoNative())

def _reference_expand(model: Model, lay: Layout, sym: bool, edges: bool = False) -> list[str]:
    """The straightforward `expand`: decode everything, every guard in turn, one set lookup per edge
    (`edges`: the same as the edge-recording `edges` function, see fastgen.expand_source)."""
    src = fastgen.head_lines(edges, "edges" if edges else "expand")
    ret = "" if edges else "nxt, "
    src.append("    for s in frontier:")
    src += _unpack_lines(model, lay, "        ")
    for i, inv in enumerate(model.invariants):
        src.append(f"        if not ({expr.to_python(inv.expr, lambda n: 'v_' + n)}):")
        src.append(f"            return {ret}('invariant', {i}, s)")
    src.append("        en = 0")
    for i, rule in enumerate(model.rules):
        src.append(f"        if {expr.to_python(rule.guard, lambda n: 'v_' + n)}:")
        lines, packed = _effect_lines(model, lay, rule, "            ")
        src += lines
        src.append(f"            ns = {packed}")
        if sym:
            src.append("            ns = canon(ns)")
        src.append("            en = 1")
        src += fastgen.edge_lines("            ", i, edges, "cov[{}]")
    src.append(f"        if not en and not ({expr.to_python(model.final, lambda n: 'v_' + n)}):")
    src.append(f"            return {ret}('deadlock', -1, s)")
    if edges:
        src.append("        eapp(len(nxt))")
    src.append(f"    return {ret}None")
    return src
