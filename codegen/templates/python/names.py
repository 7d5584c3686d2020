"""Every identifier the Python templates generate, derived with the templates' own filters.

tests/hostile/test_spec_identifiers.py walks the generated package with `ast` and
fails on any name bound there that is neither derived here nor fixed below, and on
any builtin the generated code uses that BUILTINS misses.
"""
from __future__ import annotations

import keyword
import re
from pathlib import Path
from typing import Iterator

from codegen import names as N
from codegen.model import Enum, Spec

from . import COMMON, PyMessage, camel, snake, view

# Builtins the generated modules call; a field, class or module of that name would shadow one.
BUILTINS = frozenset("""
ImportError NotImplementedError UnicodeEncodeError ValueError __name__ abs all any bool bytearray bytes classmethod dict float frozenset
getattr hash int isinstance len list min next object repr set sorted str super tuple type
""".split())

TEMPLATES = Path(__file__).resolve().parent


def bound_names(template: str, indent: str = "", attributes: bool = False) -> frozenset[str]:
    """Names a template binds at one indentation ('' module level, '    ' class bodies), read from
    its own text, so these lists follow the templates; with `attributes`, `self.x = ` counts too.
    A name that is itself templated is skipped (names.identifiers derives those)."""
    names: set[str] = set()
    text = (TEMPLATES / template).read_text(encoding="utf-8")
    for include in re.findall(r'{%\s*include\s+"([^"]+)"\s*%}', text):
        names |= bound_names(include, indent, attributes)
    for line in text.splitlines():
        if m := re.match(rf"^{indent}(?:def|class) ([A-Za-z_]\w*)(?![\w{{])", line):
            names.add(m.group(1))
        elif m := re.match(rf"^{indent}([A-Za-z_]\w*)\s*(?::[^=]*)?=(?!=)", line):
            names.add(m.group(1))
        elif m := re.match(rf"^{indent}(?:from \S+ )?import (.+)$", line):
            names |= {part.split(" as ")[-1].strip().split(".")[0] for part in m.group(1).split(",")}
        if attributes:
            names |= set(re.findall(r"self\.([A-Za-z_]\w*)\s*=(?!=)", line))
    return frozenset(names)


MESSAGES_MODULE = bound_names("messages.py.j2")
MESSAGE_CLASS = bound_names("messages.py.j2", "    ")
METHOD_LOCALS = frozenset({"self", "cls", "p", "a"})
ENUMS_MODULE = bound_names("enums.py.j2")
SKELETON_PACKAGE = frozenset({"base", "__init__"})
SKELETON_MODULE = bound_names("skeleton.py.j2")
SKELETON_CLASS = bound_names("skeleton_base.py.j2", "    ", attributes=True) | bound_names("skeleton.py.j2", "    ")


def rules() -> N.Rules:
    return N.Rules("Python", str.isidentifier, reserved)


def reserved(name: str) -> str | None:
    if keyword.iskeyword(name):
        return "a Python keyword"
    if keyword.issoftkeyword(name):
        return "a Python soft keyword"
    if name in BUILTINS:
        return "a Python builtin the generated code uses"
    return None


def _fixed(namespace: str, names: frozenset[str]) -> Iterator[N.Ident]:
    return (N.Ident(namespace, name, None) for name in sorted(names))


def identifiers(spec: Spec, msgs: list[PyMessage]) -> Iterator[N.Ident]:
    """Every module, class, attribute and local name the Python templates print from the spec."""
    module = "the Python module arachnae_proto.messages"
    yield from _fixed(module, MESSAGES_MODULE)
    for v in msgs:
        at = N.of_message(spec, v.m)
        yield N.Ident(module, v.cls, at)
        cls_ns, local_ns = f"the Python class {v.cls}", f"the methods of Python class {v.cls}"
        yield from _fixed(cls_ns, MESSAGE_CLASS)
        yield from _fixed(local_ns, METHOD_LOCALS | frozenset(u for u in v.units if u not in {f.name for f in v.fields}))
        for f in v.m.fields:
            fat = N.of_field(spec, v.m, f)
            yield N.Ident(cls_ns, f.name, fat)
            yield N.Ident(local_ns, f.name, fat)
    for e in spec.enums.values():
        yield N.Ident(module, f"_ENUM_{e.name}", N.of_enum(e))
    module = "the Python module arachnae_proto.enums"
    yield from _fixed(module, ENUMS_MODULE)
    for e in list(spec.enums.values()) + list(spec.flags.values()):
        yield N.Ident(module, camel(e.name), N.of_enum(e))
        for member in (e.values if isinstance(e, Enum) else e.bits):
            yield N.Ident(f"the Python class {camel(e.name)}", member, N.of_enum(e, member))
    for e in spec.enums.values():
        if e.texts:
            yield N.Ident(module, f"{e.name}_TEXTS", N.of_enum(e))
    package = "the Python package arachnae_proto.skeletons"
    yield from _fixed(package, SKELETON_PACKAGE)
    for role in spec.roles:
        at = N.of_role(spec, role)
        yield N.Ident(package, snake(role), at)
        module = f"the Python module arachnae_proto.skeletons.{snake(role)}"
        yield from _fixed(module, SKELETON_MODULE)
        cls = camel(role) + "Skeleton"
        yield N.Ident(module, cls, at)
        yield from _fixed(f"the Python class {cls}", SKELETON_CLASS)
        for m in spec.receives(role):
            if m.name not in COMMON:
                yield N.Ident(f"the Python class {cls}", f"on_{m.name.lower()}", N.of_message(spec, m))


def check(spec: Spec) -> list[N.Problem]:
    """What the Python target cannot generate from `spec`, at the spec item responsible."""
    problems = []
    id_ack = next((m for m in spec.messages if m.name == "ID_ACK"), None)
    if id_ack is None or [(f.name, f.type, f.is_array) for f in id_ack.fields] != [("address", "node", False)]:
        at = N.of_message(spec, id_ack) if id_ack else N.Origin("messages", ("messages",), "messages")
        problems.append(N.Problem(at, "ID_ACK must exist with one node field named address "
                                      "(seed 3.2.2; skeletons/base.py answers ID_REQ with it)"))
    msgs = [view(m) for m in spec.messages]
    return problems + N.check_identifiers(identifiers(spec, msgs), rules())
