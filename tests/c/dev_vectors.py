"""Small hand-made conformance vectors for developing the C codec (vectors.txt format).

Payload bytes are written by hand from spec/messages.yaml (not produced by the
generated code); only the opcodes, the header order and the CRC come from the spec
model (Checksum.compute is the catalogue reference), and the scaling expectations
from codegen/encoding.py, the rules both codecs must follow. The lead's full file
is generated/vectors/vectors.txt; this one only has to exist until then and keep
covering the error order.

    python tests/c/dev_vectors.py [OUT]      (default: tests/c/dev_vectors.txt)
"""
from __future__ import annotations

import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO))

from codegen.load import load_spec  # noqa: E402

SPEC = load_spec()


def frame(dst: int, src: int, name_or_opcode: str | int, payload: list[int], length: int | None = None,
          crc_delta: int = 0) -> bytes:
    opcode = SPEC.message(name_or_opcode).opcode if isinstance(name_or_opcode, str) else name_or_opcode
    values = {"dst": dst, "src": src, "opcode": opcode, "length": len(payload) if length is None else length}
    body = bytes(values[h] for h in SPEC.frame.header) + bytes(payload)
    crc = SPEC.frame.checksum.compute(body) ^ crc_delta
    return body + crc.to_bytes(SPEC.frame.crc_size, "big")


A = {n.short: n.address for n in SPEC.nodes}
BCAST = SPEC.broadcast

# (name, case, dst, src, payload, fields) -- payload bytes by hand from the spec's layouts
MSGS = [
    ("ID_ACK", "tpsc", A["SPU"], A["TPSC"], [0x28], "address=40"),
    ("INIT", "broadcast", BCAST, A["MCP"], [], ""),
    ("MOVE_RELAYED", "tripod", A["MMC"], A["MCP"], [0x02, 0x70], "address=2 mov_cmd=7 param=0"),
    ("XMIT_DATA_USRC", "typical", A["SPU"], A["USRC"], [0x80, 0x01, 0x2C], "distance=128 angle=300"),
    ("STATUS_ACK_MMC", "nibbles", A["MCP"], A["MMC"], [0x83, 0x21], "gait=8 direction=3 leg=2 error=1"),
    ("LEG_TARGET", "signed16", A["LCP(1)"], A["MMC"], [0x01, 0xFB, 0x2E, 0x01, 0xF4, 0xF4, 0x48, 0x27, 0x10],
     "phase=1 x=-1234 y=500 z=-3000 duration=10000"),
    ("XMIT_DATA_ISC", "signed8", A["SPU"], A["ISC"], [0xC4, 0x2D], "longitudinal=-60 transverse=45"),
    ("SETUP", "bitfields", A["SSC"], A["MCP"], [0x5A, 0xC8, 0xC0],
     "rate=5 amplitude=10 inflection=200 articulation=6 reserved=0"),
    ("SPEAK", "abc", A["SSC"], A["MCP"], [0x02, 0x03, 0x61, 0x62, 0x63], "repeat=2 length=3 text=97:98:99"),
    ("LCD_TEXT", "empty", A["UIC/RCP"], A["MCP"], [0x01, 0x00], "line=1 length=0 text=-"),
    ("POST_REPORT", "two", A["MCP"], A["MMC"], [0x02, 0x41, 0x2D], "missing_count=2 missing=65:45"),
    ("JOINT_FEEDBACK", "limits", A["LCP(2)"], A["JAC(2,1)"], [0xF8, 0xF8, 0x17, 0x70, 0x13, 0x88, 0xEC, 0x0D],
     "angle=-1800 speed=6000 current=5000 temperature=-20 flags=13"),
    ("UIC_ALERT", "both", A["UIC/RCP"], A["MCP"], [0x03], "alert=3"),
    ("XMIT_DATA_LSC", "100lx", A["SPU"], A["LSC"], [0xC0], "brightness=192"),
    ("XMIT_DATA_TPSC", "both", A["SPU"], A["TPSC"], [0x40], "contact=64"),
]

UNKNOWN_OPCODE = next(op for op in range(255, 0, -1) if SPEC.message_for(op) is None)


def bad_cases() -> list[tuple[str, str, bytes, str]]:
    good = frame(A["SPU"], A["USRC"], "XMIT_DATA_USRC", [0x80, 0x01, 0x2C])
    flipped = bytearray(good)
    flipped[5] ^= 0x01
    own_usrc = f"{A['USRC']:02x}"
    return [
        ("short", "-", good[:3], "TRUNCATED"),
        ("cut", "-", good[:-1], "TRUNCATED"),
        ("header_only", "-", good[:4], "TRUNCATED"),
        ("trailing", "-", good + b"\x00", "OVERSIZE"),
        ("bitflip", "-", bytes(flipped), "CHECKSUM"),
        ("crc_before_address", own_usrc, bytes(flipped), "CHECKSUM"),
        ("not_mine", own_usrc, good, "ADDRESS"),
        ("address_before_opcode", own_usrc, frame(A["SPU"], A["USRC"], UNKNOWN_OPCODE, []), "ADDRESS"),
        ("unknown_opcode", "-", frame(A["SPU"], A["USRC"], UNKNOWN_OPCODE, []), "OPCODE"),
        ("opcode_before_length", "-", frame(A["SPU"], A["USRC"], UNKNOWN_OPCODE, [1, 2, 3]), "OPCODE"),
        ("id_ack_long", "-", frame(A["SPU"], A["TPSC"], "ID_ACK", [0x28, 0x00]), "LENGTH"),
        ("length_before_range", "-", frame(A["SPU"], A["TPSC"], "ID_ACK", [0xFF, 0x00]), "LENGTH"),
        ("init_with_payload", "-", frame(BCAST, A["MCP"], "INIT", [0x00]), "LENGTH"),
        ("speak_count_disagrees", "-", frame(A["SSC"], A["MCP"], "SPEAK", [0x01, 0x03, 0x61, 0x62]), "LENGTH"),
        # the count agrees with the bytes present, but is outside 1..253: RANGE, not LENGTH
        ("speak_count_zero", "-", frame(A["SSC"], A["MCP"], "SPEAK", [0x01, 0x00]), "RANGE"),
        ("speak_short", "-", frame(A["SSC"], A["MCP"], "SPEAK", [0x01]), "LENGTH"),
        ("mov_cmd_10", "-", frame(A["MMC"], A["MCP"], "MOVE_RELAYED", [0x02, 0xA0]), "RANGE"),
        ("param_nonzero", "-", frame(A["MMC"], A["MCP"], "MOVE_RELAYED", [0x02, 0x71]), "RANGE"),
        ("not_a_node", "-", frame(A["MMC"], A["MCP"], "MOVE_RELAYED", [0x09, 0x10]), "RANGE"),
        ("broadcast_is_not_a_node", "-", frame(A["SPU"], A["TPSC"], "ID_ACK", [BCAST]), "RANGE"),
        ("angle_360", "-", frame(A["SPU"], A["USRC"], "XMIT_DATA_USRC", [0x00, 0x01, 0x68]), "RANGE"),
        ("tpsc_reserved_bit", "-", frame(A["SPU"], A["TPSC"], "XMIT_DATA_TPSC", [0x11]), "RANGE"),
        ("resident_index_11", "-", frame(A["SSC"], A["MCP"], "SPEAK_RESIDENT", [0x01, 0x00, 0x0B]), "RANGE"),
        ("gait_not_in_enum", "-", frame(A["MCP"], A["MMC"], "STATUS_ACK_MMC", [0x13, 0x00]), "RANGE"),
        ("missing_not_node", "-", frame(A["MCP"], A["MMC"], "POST_REPORT", [0x02, 0x41, 0xFF]), "RANGE"),
        ("psc_below_range", "-", frame(A["SPU"], A["PSC"], "XMIT_DATA_PSC", [39]), "RANGE"),
    ]


def scaling_lines() -> list[str]:
    out = []
    picks = {
        ("XMIT_DATA_USRC", "distance"): ([0, 1, 128, 254, 255], [-20, -19, 0, 19, 20, 39, 40, 10000, 10019, 10020]),
        ("XMIT_DATA_PSC", "voltage"): ([40, 41, 199, 200], [4197, 4198, 4200, 4202, 4203, 5002, 5003, 4000]),
        ("LEG_TARGET", "x"): ([-3000, -1, 0, 1, 3000], [-300050, -300049, -50, -49, 49, 50, 300049, 300050]),
        ("XMIT_DATA_LSC", "brightness"): ([0, 1, 64, 128, 192, 255], [0, 100, 101, 102, 1000, 1000000, 2000000]),
        ("SET_ALARM_LSC", "limit"): ([64, 255], [999, 1000, 1018, 1019, 1000000]),
    }
    for (name, fname), (raws, millis) in picks.items():
        f = SPEC.message(name).field(fname)
        lo, hi = f.raw_range
        for raw in raws:
            out.append(f"to_milli {name} {fname} {raw} {f.encoding.to_phys_milli(raw)}")
        for milli in millis:
            raw = f.encoding.to_raw_milli(milli)
            out.append(f"to_raw {name} {fname} {milli} {raw if lo <= raw <= hi else 'RANGE'}")
    return out


def render() -> str:
    lines = ["# hand-made development vectors for the C codec (tests/c/dev_vectors.py); format of generated/vectors"]
    lines.append(f"crc {b'123456789'.hex()} {SPEC.frame.checksum.check:04x}")
    lines.append(f"crc - {SPEC.frame.checksum.compute(b''):04x}")
    for data in (b"\x00", b"\xff\xff", bytes(range(256))):
        lines.append(f"crc {data.hex()} {SPEC.frame.checksum.compute(data):04x}")
    for name, case, dst, src, payload, fields in MSGS:
        lines.append(f"msg {name} {case} {frame(dst, src, name, payload).hex()} {fields}".rstrip())
    lines.extend(scaling_lines())
    for case, own, data, kind in bad_cases():
        lines.append(f"bad {case} {own} {data.hex()} {kind}")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    target = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).with_name("dev_vectors.txt")
    target.write_text(render())
