"""Conformance vectors for every codec, computed from the spec model alone.

The reference packer here is deliberately independent of both generated
codecs: a plain bit-by-bit writer over the model's field offsets. The C and the
Python codec must each reproduce these bytes and these errors exactly.
"""
from __future__ import annotations

from codegen.encoding import MILLI, Linear, Log10, round_half_away
from codegen.model import Field, Message, Spec



def pack(message: Message, values: dict[str, object]) -> bytes:
    """Reference encoder: fields MSB first at their bit offsets, arrays appended."""
    fixed_bits = sum(f.bits for f in message.fields if not f.is_array)
    acc = 0
    for f in message.fields:
        if f.is_array:
            continue
        raw = int(values[f.name])  # type: ignore[call-overload]
        acc |= (raw & ((1 << f.bits) - 1)) << (fixed_bits - f.offset_bits - f.bits)
    out = acc.to_bytes(fixed_bits // 8, "big") if fixed_bits else b""
    arr = message.array
    if arr is not None:
        out += bytes(values[arr.name])  # type: ignore[arg-type]
    return out


def frame(spec: Spec, dst: int, src: int, opcode: int, payload: bytes) -> bytes:
    head = bytes((dst, src, opcode, len(payload))) + payload
    crc = spec.frame.checksum.compute(head)
    return head + crc.to_bytes(spec.frame.crc_size, "big")


def _values(spec: Spec, m: Message, pick: str) -> dict[str, object]:
    """Field values at the low ('min') or high ('max') end, or in the middle ('mid')."""
    nodes = sorted(n.address for n in spec.nodes)
    vals: dict[str, object] = {}
    for f in m.fields:
        if f.is_array:
            continue
        vals[f.name] = _scalar(f, pick, nodes)
    arr = m.array
    if arr is not None:
        count_field = m.field(arr.count)  # type: ignore[arg-type]
        lo, hi = count_field.raw_range
        n = {"min": lo, "max": min(hi, arr.count_max), "mid": (lo + min(hi, arr.count_max)) // 2}[pick]
        vals[count_field.name] = n
        pool = nodes if arr.type == "node" else list(range(0x20, 0x7F))
        vals[arr.name] = [pool[i % len(pool)] for i in range(n)]
    return vals


def _scalar(f: Field, pick: str, nodes: list[int]) -> int:
    if f.type == "node":
        return {"min": nodes[0], "max": nodes[-1], "mid": nodes[len(nodes) // 2]}[pick]
    if f.type == "flags":
        return {"min": 0, "max": f.flags.mask, "mid": min(f.flags.bits.values())}[pick]  # type: ignore[union-attr]
    if f.type == "enum":
        values = sorted(f.enum.values.values())  # type: ignore[union-attr]
        return {"min": values[0], "max": values[-1], "mid": values[len(values) // 2]}[pick]
    lo, hi = f.raw_range
    return {"min": lo, "max": hi, "mid": (lo + hi) // 2}[pick]


def _fmt(values: dict[str, object], m: Message) -> str:
    parts = []
    for f in m.fields:
        v = values[f.name]
        if isinstance(v, (list, tuple, bytes)):
            parts.append(f"{f.name}=" + (":".join(str(x) for x in v) or "-"))
        else:
            parts.append(f"{f.name}={int(v)}")  # type: ignore[call-overload]
    return " ".join(parts)


def _route(spec: Spec, m: Message) -> tuple[int, int]:
    sender, receiver, _bus = next(iter(spec.routes(m)))
    return receiver.address, sender.address


def _message_lines(spec: Spec, m: Message) -> list[str]:
    dst, src = _route(spec, m)
    lines = []
    cases: list[tuple[str, dict[str, object]]] = [(p, _values(spec, m, p)) for p in ("min", "max", "mid")]
    for f in m.fields:
        if f.type == "enum":
            for name, value in f.enum.values.items():  # type: ignore[union-attr]
                cases.append((f"{f.name}_{name}", {**_values(spec, m, "min"), f.name: value}))
        elif f.type == "flags":
            for name, value in f.flags.bits.items():  # type: ignore[union-attr]
                cases.append((f"{f.name}_{name}", {**_values(spec, m, "min"), f.name: value}))
    seen = set()
    for case, values in cases:
        data = frame(spec, dst, src, m.opcode, pack(m, values))
        if data in seen:
            continue
        seen.add(data)
        lines.append(f"msg {m.name} {case} {data.hex()} {_fmt(values, m)}".rstrip())
    return lines


def _bad_lines(spec: Spec, m: Message) -> list[str]:
    dst, src = _route(spec, m)
    good = frame(spec, dst, src, m.opcode, pack(m, _values(spec, m, "max")))
    own = f"{dst:02x}"
    lines = [
        f"bad {m.name}_bad_checksum {own} {good[:-1].hex()}{good[-1] ^ 0x01:02x} CHECKSUM",
        f"bad {m.name}_truncated {own} {good[:-1].hex()} TRUNCATED",
        f"bad {m.name}_oversize {own} {good.hex()}00 OVERSIZE",
        f"bad {m.name}_other_address {src:02x} {good.hex()} ADDRESS",
    ]
    if m.fixed_size > 0:
        short = pack(m, _values(spec, m, "min"))[:-1] if m.array is None else pack(m, _values(spec, m, "min"))[: m.fixed_size - 1]
        lines.append(f"bad {m.name}_short_payload {own} {frame(spec, dst, src, m.opcode, short).hex()} LENGTH")
    if m.array is None:
        long_payload = pack(m, _values(spec, m, "min")) + bytes(1)
        lines.append(f"bad {m.name}_long_payload {own} {frame(spec, dst, src, m.opcode, long_payload).hex()} LENGTH")
    else:
        extra = pack(m, _values(spec, m, "min")) + b"\x41"
        lines.append(f"bad {m.name}_count_mismatch {own} {frame(spec, dst, src, m.opcode, extra).hex()} LENGTH")
    for f in m.fields:
        for case, raw in _invalid_raws(spec, f):
            values = _values(spec, m, "min")
            if f.is_array:
                values[f.name] = [raw] * max(1, len(values[f.name]))  # type: ignore[arg-type]
                values[f.count] = len(values[f.name])  # type: ignore[index, arg-type]
            else:
                values[f.name] = raw
                arr = m.array
                if arr is not None and arr.count == f.name:  # a count out of range, with that many elements
                    values[arr.name] = list(_values(spec, m, "max")[arr.name])[:1] * raw  # type: ignore[index]
            payload = pack(m, values)
            if len(payload) > spec.frame.max_payload:
                continue  # that count cannot even be framed
            data = frame(spec, dst, src, m.opcode, payload)
            lines.append(f"bad {m.name}_{f.name}_{case} {own} {data.hex()} RANGE")
    return lines


def _invalid_raws(spec: Spec, f: Field) -> list[tuple[str, int]]:
    """Raw values that fit the bits but are not valid for the field."""
    limit_lo, limit_hi = f.raw_limits
    if f.type == "node":
        known = {n.address for n in spec.nodes}
        return [("unknown_node", next(a for a in range(256) if a not in known))]
    if f.type == "char":
        return []
    if f.type == "enum":
        values = set(f.enum.values.values())  # type: ignore[union-attr]
        bad = [v for v in range(limit_lo, limit_hi + 1) if v not in values]
        return [("not_in_enum", bad[0])] if bad else []
    if f.type == "flags":
        spare = ((1 << f.bits) - 1) & ~f.flags.mask  # type: ignore[union-attr]
        return [("reserved_bits", spare & -spare)] if spare else []
    lo, hi = f.raw_range
    out = []
    if lo > limit_lo:
        out.append(("below_range", lo - 1))
    if hi < limit_hi:
        out.append(("above_range", hi + 1))
    return [(c, v & ((1 << f.bits) - 1) if v < 0 else v) for c, v in out]


INT32_MIN, INT32_MAX = -(1 << 31), (1 << 31) - 1


def _runs(valid: set[int], lo: int, hi: int) -> list[tuple[int, int]]:
    """Maximal runs of values in lo..hi that are not in `valid`, as (first, last)."""
    out: list[tuple[int, int]] = []
    for v in range(lo, hi + 1):
        if v in valid:
            continue
        if out and out[-1][1] == v - 1:
            out[-1] = (out[-1][0], v)
        else:
            out.append((v, v))
    return out


def _refused_raws(spec: Spec, f: Field) -> list[tuple[str, int]]:
    """Values an encoder must refuse for field f (one scalar, or one array element): each boundary of
    the valid set inside the field's bits (range ends, enum gaps, reserved flag bits, non-node
    addresses), just outside the bits, and far outside any 16-bit type."""
    lim_lo, lim_hi = f.raw_limits
    cases: list[tuple[str, int]] = []
    if f.type in ("uint", "int"):
        lo, hi = f.raw_range
        if lo > lim_lo:
            cases.append(("below_range", lo - 1))
        if hi < lim_hi:
            cases.append(("above_range", hi + 1))
    elif f.type in ("enum", "node"):
        valid = set(f.enum.values.values()) if f.enum is not None else {n.address for n in spec.nodes}
        for first, last in _runs(valid, lim_lo, lim_hi):
            cases += [(f"gap_{first}", first), (f"gap_{last}", last)]
    elif f.type == "flags":
        spare = ((1 << f.bits) - 1) & ~f.flags.mask  # type: ignore[union-attr]
        cases += [(f"reserved_bit{k}", 1 << k) for k in range(f.bits) if spare >> k & 1]
    cases += [("below_bits", lim_lo - 1), ("above_bits", lim_hi + 1), ("far_below", INT32_MIN), ("far_above", INT32_MAX)]
    seen: set[int] = set()
    return [(c, v) for c, v in cases if not (v in seen or seen.add(v))]  # type: ignore[func-returns-value]


def _refuse_lines(spec: Spec, m: Message) -> list[str]:
    """Values encode() must refuse with RANGE, each alone among valid ones (message 'min' values).

    Arrays always carry as many elements as their count field says: a struct with a count and
    an array cannot say anything else."""
    lines = []
    arr = m.array
    for f in m.fields:
        if arr is not None and f.name == arr.count:
            continue
        for case, raw in _refused_raws(spec, f):
            values = _values(spec, m, "min")
            if f.is_array:
                items = list(values[f.name])[:-1] if values[f.name] else []  # type: ignore[call-overload]
                values[f.name] = items + [raw]
                values[f.count] = len(values[f.name])  # type: ignore[index, arg-type]
            else:
                values[f.name] = raw
            lines.append(f"refuse {m.name} {f.name}_{case} RANGE {_fmt(values, m)}")
    if arr is not None:
        count = m.field(arr.count)  # type: ignore[arg-type]
        lo, hi = count.raw_range
        lim_hi = count.raw_limits[1]
        sizes = [("below_range", lo - 1)] if lo > 0 else []
        sizes += [("above_range", hi + 1), ("above_capacity", arr.count_max + 1), ("above_bits", lim_hi + 1)]
        pool = list(_values(spec, m, "max")[arr.name])  # type: ignore[call-overload]
        seen: set[int] = set()
        for case, n in sizes:
            if n in seen:
                continue
            seen.add(n)
            values = {**_values(spec, m, "min"), count.name: n, arr.name: [pool[i % len(pool)] for i in range(n)]}
            lines.append(f"refuse {m.name} {count.name}_{case} RANGE {_fmt(values, m)}")
    return lines


def _conversion_lines(spec: Spec, m: Message) -> list[str]:
    lines = []
    for f in m.fields:
        if f.type not in ("uint", "int") or not f.scaled:
            continue
        lo, hi = f.raw_range
        for raw in sorted({lo, hi, (lo + hi) // 2, lo + 1, hi - 1} & set(range(lo, hi + 1))):
            lines.append(f"to_milli {m.name} {f.name} {raw} {f.encoding.to_phys_milli(raw)}")
        lines += [f"to_milli {m.name} {f.name} {raw} RANGE" for raw in (lo - 1, hi + 1)]
        for milli in _milli_cases(f):
            raw = f.encoding.to_raw_milli(milli)
            ok = lo <= raw <= hi
            lines.append(f"to_raw {m.name} {f.name} {milli} {raw if ok else 'RANGE'}")
    return lines


def _milli_cases(f: Field) -> list[int]:
    """Range ends, exact halves (rounding away from zero) and just outside the range."""
    lo, hi = f.raw_range
    enc = f.encoding
    cases: set[int] = set()
    if isinstance(enc, Linear):
        for raw in (lo, hi, (lo + hi) // 2):
            exact = enc.to_phys(raw) * MILLI
            cases.update({int(exact) - 1, int(exact), int(exact) + 1})
            half = (enc.to_phys(raw) + enc.scale / 2) * MILLI
            if half.denominator == 1:
                cases.add(int(half))
            neg_half = (enc.to_phys(raw) - enc.scale / 2) * MILLI
            if neg_half.denominator == 1:
                cases.add(int(neg_half))
        cases.add(round_half_away(enc.to_phys(lo - 1) * MILLI))
        cases.add(round_half_away(enc.to_phys(hi + 1) * MILLI))
    else:
        assert isinstance(enc, Log10)
        thresholds = enc.thresholds_milli()
        for r in (1, 2, 63, 64, 65, 128, 192, len(thresholds)):
            t = thresholds[r - 1]
            cases.update({t - 1, t})
        cases.update({0, 1, thresholds[-1] * 2})
    return sorted(c for c in cases if abs(c) < 2**31)


def vector_text(spec: Spec) -> str:
    lines = [
        "# Conformance vectors for every ARACHNAE II codec (format: docs in codegen/vectors.py).",
        "#   crc <data_hex> <crc_hex>",
        "#   msg <NAME> <case> <frame_hex> <field>=<raw> ...     arrays as a:b:c, '-' when empty",
        "#   to_raw <NAME> <field> <milli> <raw|RANGE>           physical milli-units -> raw",
        "#   to_milli <NAME> <field> <raw> <milli|RANGE>         RANGE: a raw value outside the field's range",
        "#   refuse <NAME> <case> <ERROR> <field>=<raw> ...      values every encoder must refuse with ERROR, nothing sent",
        "#   bad <case> <own_address_hex> <frame_hex> <ERROR>    whole-frame check and byte parser (fed every byte, then the idle gap)",
        "# Check order: TRUNCATED/OVERSIZE, CHECKSUM, ADDRESS, ROUTE, OPCODE, LENGTH, RANGE. ADDRESS: a frame for another node;",
        "# ROUTE: a source that is no node, a destination neither node nor broadcast, broadcast on a message not marked so.",
        "# LENGTH covers a payload size the message cannot have and an array whose count disagrees with the bytes present;",
        "# a count outside its range is RANGE.",
        "# The byte parser hands a frame over when its last byte arrives; bytes before the idle gap after it are OVERSIZE.",
    ]
    crc = spec.frame.checksum
    for data in (b"123456789", b"", b"\x00", b"\xff\xff", bytes(range(32))):
        lines.append(f"crc {data.hex() or '-'} {crc.compute(data):0{crc.width // 4}x}")
    for m in spec.messages:
        lines += _message_lines(spec, m)
    for m in spec.messages:
        lines += _conversion_lines(spec, m)
    for m in spec.messages:
        lines += _bad_lines(spec, m)
    for m in spec.messages:
        lines += _refuse_lines(spec, m)
    unused = next(op for op in range(256) if spec.message_for(op) is None)
    some = spec.messages[0]
    dst, src = _route(spec, some)
    lines.append(f"bad unknown_opcode {dst:02x} {frame(spec, dst, src, unused, b'').hex()} OPCODE")
    lines.append(f"bad empty {dst:02x} - TRUNCATED")
    lines.append(f"bad header_only {dst:02x} {bytes((dst, src, some.opcode, 0)).hex()} TRUNCATED")
    bcast = next(m for m in spec.messages if m.broadcast)
    b_dst, b_src = _route(spec, bcast)
    lines.append(f"msg {bcast.name} broadcast {frame(spec, spec.broadcast, b_src, bcast.opcode, b'').hex()}")
    lines += _route_lines(spec, unused)
    return "\n".join(lines) + "\n"


def _route_lines(spec: Spec, unused_opcode: int) -> list[str]:
    """seed 3.2.1: frames whose envelope is intact but whose addresses no node of the spec could send:
    ROUTE, after ADDRESS (a frame for another node is ADDRESS whatever its source) and before OPCODE."""
    known = {n.address for n in spec.nodes}
    stranger = next(a for a in range(256) if a not in known and a != spec.broadcast)
    some = spec.messages[0]
    dst, src = _route(spec, some)
    payload = pack(some, _values(spec, some, "min"))
    single = next(m for m in spec.messages if not m.broadcast)
    s_dst, s_src = _route(spec, single)
    s_payload = pack(single, _values(spec, single, "min"))
    bc = spec.broadcast
    cases = [
        ("source_not_node", dst, frame(spec, dst, stranger, some.opcode, payload), "ROUTE"),
        ("source_broadcast", dst, frame(spec, dst, bc, some.opcode, payload), "ROUTE"),
        ("source_not_node_any", None, frame(spec, dst, stranger, some.opcode, payload), "ROUTE"),
        ("destination_not_node", None, frame(spec, stranger, src, some.opcode, payload), "ROUTE"),
        (f"{single.name}_to_broadcast", s_dst, frame(spec, bc, s_src, single.opcode, s_payload), "ROUTE"),
        (f"{single.name}_to_broadcast_any", None, frame(spec, bc, s_src, single.opcode, s_payload), "ROUTE"),
        ("unknown_opcode_to_broadcast", None, frame(spec, bc, src, unused_opcode, b""), "ROUTE"),
        ("other_node_from_stranger", src, frame(spec, dst, stranger, some.opcode, payload), "ADDRESS"),
    ]
    return [f"bad {case} {'-' if own is None else f'{own:02x}'} {data.hex()} {kind}" for case, own, data, kind in cases]


__all__ = ["vector_text", "pack", "frame"]
