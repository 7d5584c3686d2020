"""The messages of one role as a .proto for nanopb, and a driver that links their codec (issue 15.2).

    python firmware/nanopb/protos.py proto ROLE OUT.proto   messages the role sends or receives
    python firmware/nanopb/protos.py driver ROLE OUT.c      decodes what it receives, encodes what it sends

Derived from the spec, as firmware/roles.py derives the role builds: a uint, enum, flags or node
field becomes uint32, an int field sint32 (zigzag, so small negatives stay one byte), both with
nanopb's int_size of the spec's width so the C structs match ours; an array becomes a
repeated field of its count_max (nanopb keeps the count itself, so the count field is dropped).
nanopb checks the wire format only: no range, enum or address checks, no framing or CRC.
"""
from __future__ import annotations

import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO))


def _spec():
    from codegen.model import load_spec
    return load_spec()


def _role(spec, name: str) -> str:
    for r in spec.roles:
        if r.lower() == name.lower():
            return r
    raise SystemExit(f"protos.py: unknown role {name!r} (known: {', '.join(r.lower() for r in spec.roles)})")


def _type_name(msg_name: str) -> str:
    return "".join(w.capitalize() for w in msg_name.split("_"))


def _messages(spec, role: str) -> tuple[list, list]:
    return sorted(spec.receives(role), key=lambda m: m.opcode), sorted(spec.sends(role), key=lambda m: m.opcode)


def proto(spec, role: str) -> str:
    rx, tx = _messages(spec, role)
    out = [f"// Messages of role {role} for nanopb, from the spec (firmware/nanopb/protos.py). Do not edit.",
           'syntax = "proto2";', 'import "nanopb.proto";', ""]
    for m in sorted({m.name: m for m in rx + tx}.values(), key=lambda m: m.opcode):
        counts = {f.count for f in m.fields if f.is_array}
        out.append(f"// {m.name} 0x{m.opcode:02X}, seed {m.section}")
        out.append(f"message {_type_name(m.name)} {{")
        tag = 1
        for f in m.fields:
            if f.name in counts:
                continue
            ptype = "sint32" if f.signed else "uint32"
            width = 8 if f.bits <= 8 else 16 if f.bits <= 16 else 32
            opts = [f"(nanopb).int_size = IS_{width}"] if width < 32 else []
            label = "required"
            if f.is_array:
                label = "repeated"
                opts.append(f"(nanopb).max_count = {f.count_max}")
            opt = f" [{', '.join(opts)}]" if opts else ""
            out.append(f"    {label} {ptype} {f.name} = {tag}{opt};")
            tag += 1
        out.append("}")
        out.append("")
    return "\n".join(out)


def driver(spec, role: str) -> str:
    """A role's use of nanopb: every received message decoded, every sent message encoded."""
    rx, tx = _messages(spec, role)
    low = role.lower()
    out = [f"/* nanopb codec of role {role}: what the node's codec does (firmware/nanopb/protos.py). */",
           '#include "pb_encode.h"', '#include "pb_decode.h"', f'#include "{low}.pb.h"', "",
           "/* the bytes come from and go to the bus: volatile, so nothing is folded away */",
           "volatile uint8_t npb_wire[64];", "volatile uint8_t npb_len, npb_kind, npb_ok;", "",
           "static void from_wire(uint8_t *buf)", "{", "    uint8_t i;",
           "    for (i = 0; i < sizeof npb_wire; i++)", "        buf[i] = npb_wire[i];", "}", "",
           "static void to_wire(const uint8_t *buf, size_t n)", "{", "    uint8_t i;",
           "    for (i = 0; i < n && i < sizeof npb_wire; i++)", "        npb_wire[i] = buf[i];",
           "    npb_len = (uint8_t)n;", "}", "",
           "int main(void)", "{", "    uint8_t buf[sizeof npb_wire];", "    for (;;) {",
           "        from_wire(buf);", "        switch (npb_kind) {"]
    for k, m in enumerate(rx):
        t = _type_name(m.name)
        out += [f"        case {k}: {{ /* receive {m.name} */",
                f"            {t} msg = {t}_init_zero;",
                "            pb_istream_t s = pb_istream_from_buffer(buf, npb_len);",
                f"            npb_ok = (uint8_t)pb_decode(&s, {t}_fields, &msg);",
                "            break;", "        }"]
    for k, m in enumerate(tx, start=len(rx)):
        t = _type_name(m.name)
        out += [f"        case {k}: {{ /* send {m.name} */",
                f"            {t} msg = {t}_init_zero;",
                "            uint8_t o[sizeof npb_wire];",
                "            pb_ostream_t s = pb_ostream_from_buffer(o, sizeof o);",
                f"            npb_ok = (uint8_t)pb_encode(&s, {t}_fields, &msg);",
                "            to_wire(o, s.bytes_written);", "            break;", "        }"]
    out += ["        default:", "            break;", "        }", "    }", "}", ""]
    return "\n".join(out)


def main(argv: list[str]) -> int:
    if len(argv) != 3 or argv[0] not in ("proto", "driver"):
        print(__doc__, file=sys.stderr)
        return 2
    spec = _spec()
    role = _role(spec, argv[1])
    out = Path(argv[2])
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(proto(spec, role) if argv[0] == "proto" else driver(spec, role))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
