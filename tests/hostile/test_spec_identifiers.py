"""Names from the spec that would not compile or import are refused at their spec line (issue 10, item 2).

Keywords and reserved names of C and Python, builtins the generated Python uses,
names the templates define themselves, and text that is no identifier at all.
The last two tests keep the targets' lists of fixed names in step with what the
templates really print.
"""
from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

from codegen.generate import render
from codegen.load import load_spec
from codegen.templates.c import names as c_names
from codegen.templates.c import view as c_view
from codegen.templates.python import names as py_names
from codegen.templates.python import view as py_view
from tests.hostile.spec_harness import M, N, add_message, refused_everywhere, rename, replace, spec_copy

FIELD = "{name: line, type: uint"   # LCD_TEXT.line

# (id, file, edit(spec_dir), expected text in one diagnostic)
CASES = [
    ("c_keyword_field", M, lambda d: replace(d, M, FIELD, "{name: int, type: uint"), "C name int, a C keyword"),
    ("c_predefined_macro_field", M, lambda d: replace(d, M, FIELD, "{name: linux, type: uint"),
     "C name linux, a name of the C library or a predefined macro"),
    ("python_keyword_field", M, lambda d: replace(d, M, FIELD, "{name: class, type: uint"), "Python name class, a Python keyword"),
    ("python_soft_keyword_field", M, lambda d: replace(d, M, FIELD, "{name: match, type: uint"), "a Python soft keyword"),
    ("python_builtin_field", M, lambda d: replace(d, M, FIELD, "{name: len, type: uint"), "Python name len, a Python builtin"),
    ("python_self_field", M, lambda d: replace(d, M, FIELD, "{name: self, type: uint"), "Python name self in the methods of"),
    ("field_shadows_method", M, lambda d: replace(d, M, FIELD, "{name: encode, type: uint"),
     "Python name encode in the Python class LcdText, which the generated code defines itself"),
    ("role_named_base", N, lambda d: rename(d, "SSC", "BASE"),
     "Python name base in the Python package arachnae_proto.skeletons, which the generated code defines itself"),
    ("role_shadows_generic_c", N, lambda d: rename(d, "RLC", "ARACHNAE"), "C name arachnae_payload_check"),
    ("message_shadows_hook", M, lambda d: rename(d, "OBJ_BOTH", "UNHANDLED"), "Python name on_unhandled"),
    ("message_shadows_base_class", M, lambda d: rename(d, "OBJ_BOTH", "MESSAGE"), "Python name Message"),
    ("message_shadows_builtin", M, lambda d: rename(d, "OBJ_BOTH", "VALUE_ERROR"), "Python name ValueError, a Python builtin"),
    ("message_named_none", M, lambda d: rename(d, "UIC_ALERT", "NONE"), "C name none in the C union arachnae_message.u"),
    ("node_named_broadcast", N, lambda d: replace(d, N, "{short: RLC,", "{short: BROADCAST,"), "C name ARACHNAE_ADDR_BROADCAST"),
    ("short_not_an_identifier", N, lambda d: replace(d, N, "{short: RLC,", '{short: "R)C",'), "'ARACHNAE_ADDR_R)C', not a C identifier"),
    ("field_named_like_struct_type", M, lambda d: replace(d, M, FIELD, "{name: uint8_t, type: uint"), "C name uint8_t"),
    ("message_named_none_camel", M, lambda d: add_message(d, "NONE"), "Python name None, a Python keyword"),
]


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_reserved_or_invalid_name_is_refused(tmp_path: Path, case) -> None:
    _id, file, edit, expect = case
    spec_dir = spec_copy(tmp_path)
    edit(spec_dir)
    refused_everywhere(tmp_path, spec_dir, file, expect)


def _c_tokens(text: str) -> set[str]:
    text = re.sub(r"/\*.*?\*/", " ", text, flags=re.S)
    text = re.sub(r"//[^\n]*", " ", text)
    text = re.sub(r'"(\\.|[^"\\])*"', " ", text)
    text = re.sub(r"#\s*include\s*<[^>]*>|#\s*[a-z]+", " ", text)
    return {t for t in re.findall(r"[A-Za-z_]\w*|\d\w*", text) if not t[0].isdigit()}


def test_c_names_list_every_identifier_the_templates_print(spec) -> None:
    """A name printed by the C templates but unknown to c/names.py could collide unchecked."""
    vm = c_view(spec)
    known = {i.name for i in c_names.identifiers(spec, vm)} | c_names.KEYWORDS | c_names.STANDARD | {"defined"}
    fields = {f.name for m in spec.messages for f in m.fields}
    known |= fields | {f"v_{f}" for f in fields}
    printed = set()
    for path, data in render(spec, ("c",)).items():
        printed |= _c_tokens(data.decode())
    unknown = {t for t in printed - known if not c_names._STDINT_MACRO.match(t)}
    assert unknown == set(), f"add to codegen/templates/c/names.py: {sorted(unknown)}"


def _bindings(body: list[ast.stmt]) -> set[str]:
    """Names bound directly in a module or class body."""
    out: set[str] = set()
    for node in body:
        if isinstance(node, (ast.ClassDef, ast.FunctionDef)):
            out.add(node.name)
        elif isinstance(node, (ast.Import, ast.ImportFrom)):
            out |= {(a.asname or a.name).split(".")[0] for a in node.names}
        elif isinstance(node, (ast.Assign, ast.AnnAssign)):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            out |= {t.id for t in targets if isinstance(t, ast.Name)}
    return out


def _locals(fn: ast.FunctionDef) -> set[str]:
    names = {a.arg for a in fn.args.args + fn.args.kwonlyargs}
    return names | {n.id for n in ast.walk(fn) if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Store)}


def test_python_names_list_every_binding_and_builtin(spec) -> None:
    """In the namespaces the spec fills, every name the generated Python binds is one python/names.py knows;
    every builtin the generated Python reads is reserved."""
    import builtins

    msgs = [py_view(m) for m in spec.messages]
    known: dict[str, set[str]] = {}
    for ident in py_names.identifiers(spec, msgs):
        known.setdefault(ident.namespace, set()).add(ident.name)
    files = {str(p.relative_to("generated/python/arachnae_proto")): ast.parse(d.decode())
             for p, d in render(spec, ("python",)).items()}
    checked = 0
    for file, tree in files.items():
        module = "arachnae_proto." + file.removesuffix(".py").replace("/", ".")
        namespace = f"the Python module {module}"
        classes = [n for n in tree.body if isinstance(n, ast.ClassDef)]
        if namespace in known:
            assert _bindings(tree.body) <= known[namespace], (module, _bindings(tree.body) - known[namespace])
            checked += 1
        for cls in classes:
            if f"the Python class {cls.name}" in known:
                body = _bindings(cls.body) - {"__doc__"}
                assert body <= known[f"the Python class {cls.name}"], (cls.name, body - known[f"the Python class {cls.name}"])
                checked += 1
            if f"the methods of Python class {cls.name}" in known:
                for fn in (n for n in cls.body if isinstance(n, ast.FunctionDef)):
                    assert _locals(fn) <= known[f"the methods of Python class {cls.name}"], (cls.name, fn.name)
        bound = {n.id for n in ast.walk(tree) if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Store)} | _bindings(tree.body)
        read = {n.id for n in ast.walk(tree) if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Load)}
        used = {n for n in read - bound if hasattr(builtins, n)}
        assert used <= py_names.BUILTINS, f"add to python/names.py BUILTINS: {sorted(used - py_names.BUILTINS)}"
    assert checked > len(spec.messages) + len(spec.roles)   # the walk really saw the spec's classes


def test_shipped_spec_has_no_name_problem() -> None:
    spec = load_spec()
    assert c_names.check(spec) == [] and py_names.check(spec) == []
