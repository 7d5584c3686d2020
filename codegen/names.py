"""Where each generated name comes from, and the rules every generated name must follow.

A spec that passes `spec check` must generate code that compiles and imports
(issue 10, item 2). Each target therefore lists, per namespace, every identifier
it derives from the spec (with the same mangling its templates use) and the
names its templates fix; `check_identifiers` refuses keywords, reserved names,
non-identifiers and two spec items that mangle to one name (`LCP_1` and `LCP(1)`
both give ARACHNAE_ADDR_LCP_1). A target that cannot express some spec item
raises `Unsupported` while building its view model; `spec check` runs that too.
Every problem is reported at the spec line of the item it comes from.
"""
from __future__ import annotations

from typing import Callable, Iterable, NamedTuple

from codegen.model import Enum, Field, Flags, Message, Node, Spec


class Origin(NamedTuple):
    """A spec item: which file, the key path inside it (arachnae.yamlio.line_of) and what to call it."""

    file: str              # 'nodes' | 'messages'
    path: tuple
    what: str              # e.g. "node LCP(1)", "field MOVE.param"


class Ident(NamedTuple):
    """One identifier a target generates."""

    namespace: str         # names must be unique inside one namespace, e.g. "C file scope"
    name: str
    origin: Origin | None  # None: fixed by the templates
    is_file: bool = False  # a file name: only uniqueness applies


class Rules(NamedTuple):
    """What one language accepts as a name it generates."""

    language: str
    is_identifier: Callable[[str], bool]
    reserved: Callable[[str], str | None]   # why the name is reserved, or None


class Unsupported(Exception):
    """A spec item a target cannot generate code for (raised while building the target's view model)."""

    def __init__(self, origin: Origin, message: str) -> None:
        super().__init__(f"{origin.what}: {message}")
        self.origin = origin
        self.message = message


class Problem(NamedTuple):
    origin: Origin
    message: str


# -- origins of model items --------------------------------------------------------
def of_node(spec: Spec, n: Node, key: str = "short") -> Origin:
    return Origin("nodes", ("nodes", spec.nodes.index(n), key), f"node {n.short}")


def of_role(spec: Spec, role: str) -> Origin:
    first = spec.role_nodes(role)[0]
    return Origin("nodes", ("nodes", spec.nodes.index(first), "role"), f"role {role}")


def of_message(spec: Spec, m: Message, key: str = "name") -> Origin:
    return Origin("messages", ("messages", spec.messages.index(m), key), f"message {m.name}")


def of_field(spec: Spec, m: Message, f: Field, key: str = "name") -> Origin:
    return Origin("messages", ("messages", spec.messages.index(m), "fields", m.fields.index(f), key), f"field {m.name}.{f.name}")


def of_enum(e: Enum | Flags, member: str | None = None) -> Origin:
    table, values = ("enums", "values") if isinstance(e, Enum) else ("flags", "bits")
    if member is None:
        return Origin("messages", (table, e.name), f"{table[:-1]} {e.name}")
    if isinstance(e, Enum) and e.subset_of:        # a subset names its members in a list (spec enums.<E>.names)
        return Origin("messages", (table, e.name, "names", list(e.values).index(member)), f"{table[:-1]} {e.name}.{member}")
    return Origin("messages", (table, e.name, values, member), f"{table[:-1]} {e.name}.{member}")


def of_checksum(key: str) -> Origin:
    return Origin("messages", ("frame", "checksum", key), "checksum")


# -- the check ---------------------------------------------------------------------
def check_identifiers(idents: Iterable[Ident], rules: Rules) -> list[Problem]:
    """Every spec-derived name valid, not reserved, and unique in its namespace (fixed names included)."""
    problems: list[Problem] = []
    seen: dict[tuple[str, str], Ident] = {}
    for ident in idents:
        if ident.origin is not None and not ident.is_file:
            if not ident.name.isascii() or not rules.is_identifier(ident.name):
                problems.append(Problem(ident.origin, f"gives {ident.name!r}, not a {rules.language} identifier"))
                continue
            why = rules.reserved(ident.name)
            if why:
                problems.append(Problem(ident.origin, f"gives {rules.language} name {ident.name}, {why}"))
                continue
        key = (ident.namespace, ident.name)
        first = seen.setdefault(key, ident)
        if first is ident or first.origin == ident.origin:
            continue
        if first.origin is None or ident.origin is None:
            blame, clash = (ident if ident.origin is not None else first), "which the generated code defines itself"
        else:
            blame, clash = ident, f"as {first.origin.what} does"
        problems.append(Problem(blame.origin, f"gives {rules.language} name {ident.name} in {ident.namespace}, {clash}"))  # type: ignore[arg-type]
    return problems
