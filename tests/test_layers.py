"""The layout is the architecture (docs/architecture.md): spec -> codegen -> generated -> behaviours ->
firmware / captures / model_check -> console (the host's terminal line) / tracecheck -> sim2d, with the
entry points (`arachnae.cli`, `python -m console`) on top. Every import counts,
function-local ones too, so no dependency upward and no cycle can hide behind a deferred import."""
from __future__ import annotations

import ast
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent
ROOTS = {"arachnae": REPO / "arachnae", "codegen": REPO / "codegen", "arachnae_proto": REPO / "generated" / "python" / "arachnae_proto",
         "behaviours": REPO / "behaviours", "firmware": REPO / "firmware", "captures": REPO / "captures",
         "model_check": REPO / "model_check", "tracecheck": REPO / "tracecheck", "sim2d": REPO / "sim2d",
         "console": REPO / "console"}
# Lower number = lower layer; a package imports only packages of a lower layer (and itself).
LAYER = {"arachnae": 0, "codegen": 1, "arachnae_proto": 2, "behaviours": 3, "firmware": 4, "captures": 4,
         "model_check": 4, "console": 5, "tracecheck": 5, "sim2d": 6}
TOP = {"arachnae.cli", "arachnae.__main__", "console.__main__"}      # entry points assemble every part


def modules() -> dict[str, Path]:
    out = {}
    for pkg, root in ROOTS.items():
        for f in root.rglob("*.py"):
            parts = (pkg,) + f.relative_to(root).with_suffix("").parts
            name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
            out[name] = f
    return out


def _is_type_checking(test: ast.expr) -> bool:
    return isinstance(test, ast.Name) and test.id == "TYPE_CHECKING" or \
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING"


def imports(name: str, path: Path, known: dict[str, Path]) -> set[str]:
    """The project modules `name` imports anywhere in its body."""
    found = set()
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    tree = ast.parse(path.read_text(encoding="utf-8"))
    typing_only = {id(n) for block in ast.walk(tree) if isinstance(block, ast.If) and _is_type_checking(block.test)
                   for stmt in block.body for n in ast.walk(stmt)}
    for node in ast.walk(tree):
        if id(node) in typing_only:      # `if TYPE_CHECKING:` imports exist for annotations only, never at run time
            continue
        targets = []
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                base = ".".join(package.split(".")[: len(package.split(".")) - node.level + 1] + ([base] if base else []))
            targets = [f"{base}.{a.name}" if f"{base}.{a.name}" in known else base for a in node.names]
        for t in targets:
            while t and t not in known:
                t = t.rpartition(".")[0]
            if t and t != name:
                found.add(t)
    return found


MODULES = modules()
GRAPH = {name: imports(name, path, MODULES) for name, path in MODULES.items()}


def test_no_package_imports_a_higher_layer():
    wrong = sorted(f"{m} -> {t}" for m, ts in GRAPH.items() if m not in TOP for t in ts
                   if t.split(".")[0] != m.split(".")[0] and LAYER[t.split(".")[0]] >= LAYER[m.split(".")[0]])
    assert wrong == []


def test_no_import_cycle():
    index, low, stack, on, cycles = {}, {}, [], set(), []

    def visit(v):                       # Tarjan's strongly connected components
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in sorted(GRAPH.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                cycles.append(sorted(comp))
    import sys
    sys.setrecursionlimit(10000)
    for v in sorted(GRAPH):
        if v not in index:
            visit(v)
    # a package's __init__ re-exporting its own modules is not a cycle of meaning
    cycles = [c for c in cycles if not all(m == c[0].split(".")[0] or m.startswith(c[0].split(".")[0] + ".") for m in c)
              or not any(m == c[0].split(".")[0] for m in c)]
    assert cycles == []


@pytest.mark.parametrize("pkg", ["codegen"])
def test_the_generator_does_not_import_its_output(pkg):
    assert not [f"{m} -> {t}" for m, ts in GRAPH.items() if m.split(".")[0] == pkg for t in ts if t.startswith("arachnae_proto")]
