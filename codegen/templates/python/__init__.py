"""Python target: a standard-library-only codec package, `arachnae_proto`.
The view model below turns each message into struct formats and ready-made
expressions, so the templates only loop and branch (DEVELOPERS.md, Style).
Hot paths (frame check, decode) are straight-line code per message: the
benchmark target is 300,000 typical frames/s on CPython.
"""
from __future__ import annotations

import re
from dataclasses import dataclass

from codegen.encoding import Linear, Log10
from codegen.generate import Output
from codegen.model import ERROR_KINDS, Field, Message, Spec

from . import filters

OUT_DIR = "generated/python/arachnae_proto"
COMMENT = "#"


# seed 3.2.2-3.2.3: the requests every node answers alike, handled by skeletons/base.py (skeleton.py.j2 skips them)
COMMON = ("INIT", "ID_REQ", "STATUS_REQ")


def camel(name: str) -> str:
    return "".join(part.capitalize() for part in name.lower().split("_"))


def snake(name: str) -> str:
    return re.sub(r"[^a-z0-9]+", "_", name.lower()).strip("_")


@dataclass
class Rule:
    """One field's row in the encode table: a valid raw value is an integer in lo..hi with no `spare`
    bit set and, if `allowed` names a set (enum values, node addresses), in it."""

    lo: int
    hi: int
    allowed: str        # Python expression of a frozenset, or "None"
    spare: int
    expect: str         # what a valid value is, for the error message


@dataclass
class PyField:
    name: str
    type: str
    bits: int
    check: str          # Python condition on the field's variable, true when invalid ('' = always valid)
    expect: str         # what a valid value is, for the error message
    default: str | None # constructor default, when the field has exactly one valid value
    is_count: bool
    enum: str | None
    flags: str | None
    unit: str
    scaled: bool
    conv: str           # constructor of the field's converter in the runtime
    doc: str
    rule: Rule          # what encode() accepts (messages.FieldInfo)
    count_max: int      # arrays: capacity


@dataclass
class PyMessage:
    m: Message
    cls: str
    fmt: str                      # struct format of the fixed part
    units: list[str]              # unpack target names, one per struct item
    decode_exprs: list[tuple[str, str]]   # (field, expression over units)
    encode_units: list[str]       # expressions over field names, one per struct item
    fields: list[PyField]
    array: PyField | None
    count_field: str | None


def _check(f: Field) -> tuple[str, str]:
    """A condition on the variable named like the field, true when its raw value is invalid."""
    v = f.name
    if f.type == "enum":
        return f"{v} not in _ENUM_{f.enum.name}", f"one of {f.enum.name}"  # type: ignore[union-attr]
    if f.type == "flags":
        mask = f.flags.mask  # type: ignore[union-attr]
        return f"{v} & 0x{(~mask) & ((1 << f.bits) - 1):X}", f"flags of {f.flags.name} (mask 0x{mask:X})"  # type: ignore[union-attr]
    if f.type == "node":
        if f.is_array:
            return f"any(a not in NODE_ADDRESSES for a in {v})", "node addresses"
        return f"{v} not in NODE_ADDRESSES", "a node address"
    if f.type == "char":
        return "", ""
    lo, hi = f.raw_range
    if (lo, hi) == f.raw_limits:
        return "", ""
    if lo == hi:
        return f"{v} != {lo}", f"{lo}"
    return f"not {lo} <= {v} <= {hi}", f"{lo}..{hi}"


def _rule(f: Field) -> Rule:
    """The same acceptance as the C codec's encode checks (codegen/templates/c: FieldView.conds)."""
    if f.type == "enum":
        lo, hi = f.raw_range
        return Rule(lo, hi, f"_ENUM_{f.enum.name}", 0, f"one of {f.enum.name}")  # type: ignore[union-attr]
    if f.type == "flags":
        hi = (1 << f.bits) - 1
        mask = f.flags.mask  # type: ignore[union-attr]
        return Rule(0, hi, "None", hi & ~mask, f"flags of {f.flags.name} (mask 0x{mask:X})")  # type: ignore[union-attr]
    if f.type == "node":
        return Rule(0, 255, "NODE_ADDRESSES", 0, "node addresses" if f.is_array else "a node address")
    if f.type == "char":
        return Rule(0, 255, "None", 0, "bytes or Latin-1 text")
    lo, hi = f.raw_range
    return Rule(lo, hi, "None", 0, f"{lo}" if lo == hi else f"an integer {lo}..{hi}")


def _conv(f: Field) -> str:
    lo, hi = f.raw_range
    if isinstance(f.encoding, Log10):
        return f"LogConv(_tables.{table_name(f)}_THRESHOLDS, _tables.{table_name(f)}_PHYS, {lo}, {hi})"
    enc: Linear = f.encoding  # type: ignore[assignment]
    return (f"LinearConv({enc.scale.numerator}, {enc.scale.denominator}, "
            f"{enc.offset.numerator}, {enc.offset.denominator}, {lo}, {hi})")


def table_name(f: Field) -> str:
    """Log tables are shared by every field with the same encoding."""
    enc: Log10 = f.encoding  # type: ignore[assignment]
    return f"LOG10_{str(enc.ref).replace('/', '_')}_{enc.per_decade}_{enc.raw_max}"


def _sign(expr: str, bits: int) -> str:
    return f"(({expr}) ^ {1 << (bits - 1)}) - {1 << (bits - 1)}"


def view(m: Message) -> PyMessage:
    fmt, units, decode_exprs, encode_units = ">", [], [], []
    group: list[Field] = []

    def flush_group() -> None:
        if not group:
            return
        unit = f"u{len(units)}"
        units.append(unit)
        fmt_char = "B"
        parts = []
        shift = 8
        for g in group:
            shift -= g.bits
            mask = (1 << g.bits) - 1
            expr = f"({unit} >> {shift}) & 0x{mask:X}" if shift else f"{unit} & 0x{mask:X}"
            decode_exprs.append((g.name, _sign(expr, g.bits) if g.signed else expr))
            val = f"({g.name} & 0x{mask:X})" if g.signed else g.name
            parts.append(f"({val} << {shift})" if shift else val)
        encode_units.append(" | ".join(parts))
        nonlocal fmt
        fmt += fmt_char
        group.clear()

    fixed = [f for f in m.fields if not f.is_array]
    for f in fixed:
        if f.bits in (8, 16) and f.byte_aligned:
            flush_group()
            fmt += {8: "B", 16: "H"}[f.bits].lower() if f.signed else {8: "B", 16: "H"}[f.bits]
            units.append(f.name)
            decode_exprs.append((f.name, f.name))
            encode_units.append(f.name)
        else:
            group.append(f)
            if sum(g.bits for g in group) == 8:
                flush_group()
    flush_group()
    count_names = {f.count for f in m.fields if f.count}
    fields = []
    for f in m.fields:
        check, expect = _check(f)
        lo, hi = f.raw_range
        default = str(lo) if lo == hi and f.type in ("uint", "int") else None
        fields.append(PyField(
            name=f.name, type=f.type, bits=f.bits, check=check, expect=expect, default=default,
            is_count=f.name in count_names, enum=f.enum.name if f.enum else None,
            flags=f.flags.name if f.flags else None, unit=f.unit, scaled=f.scaled,
            conv=_conv(f) if f.type in ("uint", "int") else "None", doc=f.doc,
            rule=_rule(f), count_max=f.count_max))
    array = next((pf for pf in fields if pf.name == (m.array.name if m.array else None)), None)
    if array is not None and array is not fields[-1]:
        raise ValueError(f"{m.name}: the Python codec supports one array, as the last field")
    return PyMessage(m, camel(m.name), fmt, units, decode_exprs, encode_units, fields, array,
                     m.array.count if m.array else None)


def log_tables(spec: Spec) -> dict[str, Log10]:
    tables: dict[str, Log10] = {}
    for m in spec.messages:
        for f in m.fields:
            if isinstance(f.encoding, Log10):
                tables[table_name(f)] = f.encoding
    return dict(sorted(tables.items()))


def chunks(values: list[int], n: int = 12) -> list[str]:
    return [", ".join(str(v) for v in values[i:i + n]) for i in range(0, len(values), n)]


def crc_fast(spec: Spec) -> bool:
    """binascii.crc_hqx computes exactly the non-reflected CRC-16 with poly 0x1021 (any init)."""
    c = spec.frame.checksum
    return (c.width, c.poly, c.refin, c.refout, c.xorout) == (16, 0x1021, False, False, 0)


FILTERS = {"camel": camel, "snake": snake, "hex2": lambda v: f"0x{v:02X}", "chunks": chunks,
           "pytuple": lambda xs: repr(tuple(xs)), **filters.FILTERS}


def outputs(spec: Spec) -> list[Output]:
    msgs = [view(m) for m in spec.messages]
    roles = []
    for role in spec.roles:
        status = spec.reply("STATUS_REQ", role)          # skeletons/base.py answers STATUS_REQ with it
        roles.append({
            "role": role, "module": snake(role), "cls": camel(role) + "Skeleton",
            "receives": [v for v in msgs if role in v.m.receivers],
            "status": next((v for v in msgs if status is not None and v.m.name == status.name), None),
            "nodes": spec.role_nodes(role),
        })
    routes = {}
    for n in spec.nodes:
        routes[n.address] = {o.address: spec.shared_bus(n, o).name for o in spec.nodes  # type: ignore[union-attr]
                             if o is not n and spec.shared_bus(n, o) is not None}
    # seed 3.2.2: per fetch message, the records each slave role answers it with (spec `record: true`)
    fetched: dict[str, dict[str, list[str]]] = {}
    for bus in spec.buses.values():
        if bus.fetch_message is not None:
            by_role = fetched.setdefault(camel(bus.fetch_message), {})
            for role, records in spec.fetched_records(bus.name).items():
                by_role.setdefault(role, [camel(m.name) for m in records])
    # seed 3.2.2, 6.2: per sensor role, the fields its records carry (messages.<m>.record_values) and the threshold
    # that is compared with them (a field's compared_with); the lint allows one of each per role
    record_values = [{"role": m.senders[0], "cls": camel(m.name), "fields": m.record_values, "channel": m.record_channel}
                     for m in spec.messages if m.record_values]
    thresholds = [{"role": spec.message(f.compared_with).senders[0], "cls": camel(m.name), "limit": f.name}
                  for m in spec.messages for f in m.fields if f.compared_with is not None]
    width = spec.frame.checksum.width
    ctx = {"errors": ERROR_KINDS, "msgs": msgs, "fetched": fetched, "record_values": record_values, "thresholds": thresholds, "common": COMMON, "roles": roles, "tables": log_tables(spec), "crc_fast": crc_fast(spec), "routes": routes,
           "crc_shift": width - 8, "crc_top": 1 << (width - 1), "crc_mask": (1 << width) - 1}
    out = [
        Output("__init__.py", "init.py.j2", ctx),
        Output("errors.py", "errors.py.j2", ctx),
        Output("network.py", "network.py.j2", ctx),
        Output("enums.py", "enums.py.j2", ctx),
        Output("_tables.py", "tables.py.j2", ctx),
        Output("convert.py", "convert.py.j2", ctx),
        Output("messages.py", "messages.py.j2", ctx),
        Output("frame.py", "frame.py.j2", ctx),
        Output("skeletons/__init__.py", "skeletons_init.py.j2", ctx),
        Output("skeletons/base.py", "skeleton_base.py.j2", ctx),
    ]
    out += [Output(f"skeletons/{r['module']}.py", "skeleton.py.j2", {**ctx, "r": r}) for r in roles]
    return out
