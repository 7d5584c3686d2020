"""Messages the spec declares but no role's implementation sends or handles (issue 10: a lint warning).

The spec says which roles send and receive each message (`from` / `to`); whether
any role's implementation does lives above codegen: behaviours/ (the node logic),
console/, sim2d/ and firmware/. Those layers may not be imported from here, so
their sources are read as text and searched for the names the generators give a
message: its Python class (ObjLeft), skeleton hook (on_obj_left), C functions
(arachnae_obj_left_*) and opcode macro (ARACHNAE_OP_OBJ_LEFT). A message none of
them mentions is dead weight in the protocol: `spec check` warns, naming it. A message
whose code travels inside another one (`carriers`) is used when that one is.
"""
from __future__ import annotations

import re
from pathlib import Path

from arachnae.errors import located
from codegen.generate import REPO
from codegen.model import Message, Spec
from codegen.templates.c import MessageView
from codegen.templates.python import camel
from arachnae.yamlio import line_of, load_yaml

IMPLEMENTATION = ("behaviours", "console", "sim2d", "firmware")
SOURCES = (".py", ".c", ".h")


def _implementation_text(root: Path) -> str:
    parts = []
    for top in IMPLEMENTATION:
        for path in sorted((root / top).rglob("*")):
            if path.suffix in SOURCES and path.is_file() and "build" not in path.relative_to(root).parts:
                parts.append(path.read_text(encoding="utf-8", errors="replace"))
    return "\n".join(parts)


def carriers(spec: Spec) -> dict[str, str]:
    """Messages whose code travels inside another message: name -> that carrier's name (spec
    messages.<m>.carried_in, linted; seed 3.2.12: the TPSC's OBJ_LEFT, OBJ_RIGHT and OBJ_BOTH are the
    TPSC_CONTACT bits of XMIT_DATA_TPSC.contact)."""
    return {m.name: m.carried_in for m in spec.messages if m.carried_in is not None}


def unused_messages(spec: Spec, root: Path = REPO) -> list[str]:
    """Names of the messages no implementation under `root` refers to, in spec order; a message carried as a
    code inside another (carriers) counts as used when its carrier is."""
    text = _implementation_text(root)

    def mentioned(m: Message) -> bool:
        c = MessageView(m, spec.frame.overhead, spec)
        names = (camel(m.name), f"on_{m.name.lower()}", f"{c.prefix}_\\w+", c.op_macro)
        return re.search(r"\b(" + "|".join(names) + r")\b", text) is not None

    used = {m.name for m in spec.messages if mentioned(m)}
    carried = carriers(spec)
    return [m.name for m in spec.messages if m.name not in used and carried.get(m.name) not in used]


def warnings(spec: Spec, root: Path = REPO) -> list[str]:
    """One `file:line: warning: ...` per unused message, at its `name` in messages.yaml."""
    unused = set(unused_messages(spec, root))
    if not unused:
        return []
    path = spec.sources[1]
    doc = load_yaml(path)
    return [located(str(path), line_of(doc, ["messages", i, "name"]),
                    f"warning: {m.name} is declared (from {', '.join(m.senders)} to {', '.join(m.receivers)}) "
                    f"but no role's implementation ({', '.join(IMPLEMENTATION)}) sends or handles it")
            for i, m in enumerate(spec.messages) if m.name in unused]
