"""C99 target for 8-bit microcontrollers (issue 2): codec, frame parser, reflection, node skeletons.

The view model below turns the spec model into names, masks, shifts, conditions and
tables, so the Jinja templates only loop and branch. Layout of the output:
  arachnae.h           constants, message structs, every prototype
  arachnae_frame.c     CRC, frame building/checking, byte-at-a-time parser
  msg_<name>.c         one message: validate/decode/check/encode/build, scaling helpers
  log10_<k>.c          one logarithmic encoding's threshold tables (seed 3.2.16)
  arachnae_generic.[ch] tagged union, field descriptors, generic encode/decode (tools/tests)
  node_<role>.[ch]     node skeleton: typed dispatch of what the role receives
One .c per message lets any toolchain leave out what a role does not use, even
without -ffunction-sections (archive members are only linked when referenced).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from fractions import Fraction
from math import lcm

from codegen import names as N
from codegen.encoding import MILLI, Linear, Log10
from codegen.generate import Output
from codegen.model import ERROR_KINDS, Field, Message, Spec

from . import filters

from .filters import INT32_MAX, INT32_MIN, INT64_MAX, INT64_MIN, c_int, ctype_of, hex_u, pack_term, extract_term

OUT_DIR = "generated/c"
COMMENT = "//"
FILTERS = filters.FILTERS

# Protocol messages whose handling the skeletons generate (seed 3.2.2/3.2.3).
INIT, ID_REQ, ID_ACK, STATUS_REQ, STATUS_ACK = "INIT", "ID_REQ", "ID_ACK", "STATUS_REQ", "STATUS_ACK"


def _search(lo: int, hi: int, pred) -> int | None:
    """Smallest x in [lo, hi] with pred(x) (pred monotonic False..True), None if none."""
    if not pred(hi):
        return None
    while lo < hi:
        mid = (lo + hi) // 2
        if pred(mid):
            hi = mid
        else:
            lo = mid + 1
    return lo


@dataclass
class Log10Table:
    index: int
    enc: Log10
    thresholds: list[int]
    phys: list[int]

    @property
    def prefix(self) -> str:
        return f"arachnae_log10_{self.index}"

    @property
    def file(self) -> str:
        return f"log10_{self.index}.c"


@dataclass
class Scaled:
    """Raw <-> milli helpers of one field, exactly codegen/encoding.py's rules."""

    kind: str                  # 'linear' | 'log10'
    to_milli: str              # C function names
    from_milli: str
    doc: str
    # linear: milli = rdiv(raw*A + B, D); raw = rdiv(milli*E + F, G) after milli in [mlo, mhi]
    A: int = 0
    B: int = 0
    D: int = 1
    E: int = 0
    F: int = 0
    G: int = 1
    mlo: int | None = None     # None: no bound needed
    mhi: int | None = None
    to_wide: bool = False      # int64 arithmetic needed
    from_wide: bool = False
    table: Log10Table | None = None
    raw_lo_check: int | None = None   # log10: raw bounds to enforce
    raw_hi_check: int | None = None

    @property
    def to_rdiv(self) -> str:
        return "arachnae_rdiv64" if self.to_wide else "arachnae_rdiv32"

    @property
    def from_rdiv(self) -> str:
        return "arachnae_rdiv64" if self.from_wide else "arachnae_rdiv32"

    @property
    def to_t(self) -> str:
        return "int64_t" if self.to_wide else "int32_t"

    @property
    def from_t(self) -> str:
        return "int64_t" if self.from_wide else "int32_t"

    def lit_to(self, v: int) -> str:
        return filters.i64(v) if self.to_wide else filters.i32(v)

    def lit_from(self, v: int) -> str:
        return filters.i64(v) if self.from_wide else filters.i32(v)


class FieldView:
    def __init__(self, f: Field, msg_lname: str, index: int, origin: N.Origin):
        self.f = f
        self.origin = origin
        self.index = index
        self.name = f.name
        self.kind = f.type
        self.bits = f.bits
        self.ctype, self.cmin, self.cmax, self.cbits = ctype_of(f.bits, f.signed)
        self.signed = f.signed
        self.is_array = f.is_array
        self.count = f.count
        self.count_max = f.count_max
        self.raw_lo, self.raw_hi = f.raw_range
        self.lim_lo, self.lim_hi = f.raw_limits
        self.pieces = filters.pieces(f.offset_bits, f.bits) if not f.is_array else []
        self.byte = f.offset_bits // 8
        self.scaled: Scaled | None = None
        self.prefix = f"arachnae_{msg_lname}_{f.name}"
        self.unit = f.unit
        self.doc = f.doc

    @property
    def kind_macro(self) -> str:
        return f"ARACHNAE_KIND_{self.kind.upper()}"

    @property
    def ctype_macro(self) -> str:
        return "ARACHNAE_CTYPE_" + self.ctype.replace("_t", "").upper()

    @property
    def comment(self) -> str:
        parts = [self.kind]
        if self.f.enum is not None:
            parts.append(f"enum {self.f.enum.name}")
        if self.f.flags is not None:
            parts.append(f"flags {self.f.flags.name}")
        if self.f.range is not None:
            lo, hi = self.f.range
            parts.append(f"{_fmt(lo)}..{_fmt(hi)} {self.unit}".rstrip())
        if self.f.scaled:
            parts.append(f"raw {self.raw_lo}..{self.raw_hi}")
        if self.is_array:
            parts.append(f"count in '{self.count}'")
        if self.doc:
            parts.append(self.doc)
        return "; ".join(parts)

    def lit(self, v: int) -> str:
        return c_int(v, unsigned=not self.signed)

    def conds(self, v: str, implied: tuple[int, int], width_bits: int) -> list[str]:
        """C conditions that hold iff value `v` is valid; comparisons implied by `implied` are left out."""
        lo_lim, hi_lim = implied
        f = self.f
        if f.type == "node":
            return [f"arachnae_is_node({v})"]
        if f.type == "flags":
            assert f.flags is not None
            inv = ((1 << width_bits) - 1) & ~f.flags.mask
            return [f"(((unsigned){v}) & {hex_u(inv)}) == 0u"] if inv else []
        if f.type == "enum":
            assert f.enum is not None
            vals = sorted(set(f.enum.values.values()))
            if vals != list(range(vals[0], vals[-1] + 1)):
                return ["(" + " || ".join(f"{v} == {self.lit(x)}" for x in vals) + ")"]
        out = []
        if self.raw_lo > lo_lim:
            out.append(f"{v} >= {self.lit(self.raw_lo)}")
        if self.raw_hi < hi_lim:
            out.append(f"{v} <= {self.lit(self.raw_hi)}")
        return out

    def check_conds(self, v: str) -> list[str]:
        """For a struct member about to be encoded: anything the C type can hold but the field cannot."""
        return self.conds(v, (self.cmin, self.cmax), self.cbits)

    def wire_conds(self, v: str) -> list[str]:
        """For a value just read from the wire: the bits already bound it."""
        return self.conds(v, (self.lim_lo, self.lim_hi), self.bits)

    def extract(self, buf: str = "p", base: str = "") -> str:
        """Typed C expression reading this field from a payload buffer."""
        terms = [extract_term(pc, buf, base) for pc in self.pieces]
        raw = " | ".join(terms) if len(terms) > 1 else terms[0]
        if self.signed:
            sign, mask = 1 << (self.bits - 1), (1 << self.bits) - 1
            return f"({self.ctype})arachnae_sext((uint16_t)({raw}), {hex_u(sign)}, {hex_u(mask)})"
        return f"({self.ctype})({raw})"


def _fmt(v: Fraction) -> str:
    return str(v.numerator) if v.denominator == 1 else str(float(v)) if len(str(float(v))) < 10 else str(v)


class MessageView:
    def __init__(self, m: Message, frame_overhead: int, spec: Spec):
        self.m = m
        self.origin = N.of_message(spec, m)
        self.name = m.name
        self.lname = m.name.lower()
        self.opcode = m.opcode
        self.op_macro = f"ARACHNAE_OP_{m.name}"
        self.min_size, self.max_size, self.fixed_size = m.min_size, m.max_size, m.fixed_size
        self.frame_max = frame_overhead + m.max_size
        self.type = f"arachnae_{self.lname}_t"
        self.prefix = f"arachnae_{self.lname}"
        self.file = f"msg_{self.lname}.c"
        self.fields = [FieldView(f, self.lname, i, N.of_field(spec, m, f)) for i, f in enumerate(m.fields)]
        arrays = [fv for fv in self.fields if fv.is_array]
        if len(arrays) > 1 or (arrays and arrays[0] is not self.fields[-1]):
            raise ValueError(f"{m.name}: the C codec supports one array, as the last field")
        self.array = arrays[0] if arrays else None
        self.count_field = next(fv for fv in self.fields if fv.name == self.array.count) if self.array else None
        self.fixed_fields = [fv for fv in self.fields if not fv.is_array]
        self.section, self.doc, self.origin = m.section, m.doc, m.origin
        self.senders, self.receivers = m.senders, m.receivers

    @property
    def has_fields(self) -> bool:
        return bool(self.fields)

    @property
    def scaled_fields(self) -> list[FieldView]:
        return [fv for fv in self.fields if fv.scaled is not None]

    @property
    def checked_fixed(self) -> list[FieldView]:
        """Fixed fields whose wire value needs a check on decode."""
        return [fv for fv in self.fixed_fields if fv.wire_conds("v")]

    @property
    def count_needs_cap(self) -> bool:
        """The count field's range allows more elements than fit (encode must refuse them)."""
        return self.array is not None and self.count_field.raw_hi > self.array.count_max

    @property
    def length_bad(self) -> str:
        """C condition on `len` that makes the payload size impossible for this message.

        As the Python codec: a message without array has exactly its fixed size; one with
        an array has at least the fixed part, and its count field must then agree with the
        bytes that follow (LENGTH); a count outside the count field's range is RANGE.
        """
        if self.array is None:
            return f"len != {self.fixed_size}u"
        return f"len < {self.fixed_size}u" if self.fixed_size > 0 else "0"

    @property
    def check_fixed(self) -> list[tuple[FieldView, str]]:
        """(field, condition) for struct members to check before encoding."""
        out = []
        for fv in self.fixed_fields:
            conds = fv.check_conds(f"m->{fv.name}")
            if conds:
                out.append((fv, " && ".join(conds)))
        return out

    @property
    def wire_fixed(self) -> list[tuple[FieldView, str]]:
        """(field, condition on local v_<name>) for wire values to check after decoding."""
        out = []
        for fv in self.fixed_fields:
            conds = fv.wire_conds(f"v_{fv.name}")
            if conds:
                out.append((fv, " && ".join(conds)))
        return out

    @property
    def array_check(self) -> str:
        return " && ".join(self.array.check_conds(f"m->{self.array.name}[i]")) if self.array else ""

    @property
    def array_wire(self) -> str:
        return " && ".join(self.array.wire_conds(f"payload[{self.fixed_size}u + i]")) if self.array else ""

    @property
    def size_expr(self) -> str:
        """C expression: payload bytes of the checked struct `m` (fixed part plus the array's count)."""
        if self.array is None:
            return f"{self.fixed_size}u"
        return f"(uint16_t)({self.fixed_size}u + m->{self.count_field.name})"

    def pack_bytes(self, m: str = "m") -> list[tuple[int, str]]:
        """(payload byte index, C expression) for every byte of the fixed part."""
        out = []
        for b in range(self.fixed_size):
            terms = [pack_term(pc, f"{m}->{fv.name}") for fv in self.fixed_fields for pc in fv.pieces if pc.byte == b]
            out.append((b, "(uint8_t)(" + " | ".join(terms) + ")"))
        return out


@dataclass
class RoleView:
    role: str
    lname: str
    nodes: list[tuple[str, int]]
    receives: list[MessageView]
    rx_max: int
    addr_cond: str
    init: MessageView | None = None
    id_req: MessageView | None = None
    id_ack: MessageView | None = None
    id_ack_field: str = ""
    status_req: MessageView | None = None
    status_ack: MessageView | None = None
    others: list[MessageView] = field(default_factory=list)
    replies: dict[str, MessageView] = field(default_factory=dict)   # request name -> its reply (reply_to), others only

    @property
    def node_t(self) -> str:
        return f"{self.lname}_node"

    @property
    def guard(self) -> str:
        return f"ARACHNAE_NODE_{self.role.upper()}_H"

    @property
    def multi_address(self) -> bool:
        """More than one node has this role: its parser keeps the own address (node_<role>.h)."""
        return len(self.nodes) > 1

    @property
    def rx_count_t(self) -> str:
        """Type of the role parser's byte count: 8 bits where the role's largest frame allows (AVR flash)."""
        return "uint8_t" if self.rx_max <= 0xFF else "uint16_t"

    @property
    def rx_init(self) -> str:
        return f"{self.role.upper()}_RX_INIT"

    @property
    def empty_receives(self) -> list[MessageView]:
        """Received messages without fields: one shared `len != 0` check in the payload check."""
        return [m for m in self.receives if not m.has_fields]

    @property
    def field_others(self) -> list[MessageView]:
        """Received messages with fields that reach a behaviour callback (decoded into node->msg)."""
        return [m for m in self.others if m.has_fields]

    @property
    def field_receives(self) -> list[MessageView]:
        return [m for m in self.receives if m.has_fields]

    @property
    def answers(self) -> bool:
        """The skeleton answers some request itself (one reply buffer, one seal, one send)."""
        return bool(self.id_req or self.status_req or self.replies)

    @property
    def reply_has_array(self) -> bool:
        """Some reply is checked and packed through its functions (an array: not inlined)."""
        return any(m.array for m in [self.status_ack, *self.replies.values()] if m is not None)

    @property
    def reply_max(self) -> int:
        return max([m.frame_max for m in (self.id_ack, self.status_ack, *self.replies.values()) if m is not None] or [0])


@dataclass
class FrameView:
    dst: int
    src: int
    opcode: int
    length: int
    header_size: int
    crc_size: int
    overhead: int
    max_payload: int
    max_frame: int
    crc_name: str
    crc_poly: int
    crc_init: int
    crc_xorout: int
    crc_reflected: bool
    crc_fast_1021: bool
    crc_check: int

    @property
    def crc_residue_zero(self) -> bool:
        """The CRC over header, payload and the big-endian CRC itself is 0 for a good frame
        (MSB-first CRC, no xorout), so the check needs no second read of the CRC bytes."""
        return not self.crc_reflected and self.crc_xorout == 0


def _frame_view(spec: Spec) -> FrameView:
    fr = spec.frame
    need = ("dst", "src", "opcode", "length")
    if sorted(fr.header) != sorted(need):
        raise ValueError(f"the C codec expects header fields {need}, spec has {fr.header}")
    if fr.byte_order != "big" or fr.covers != fr.header + ("payload",):
        raise ValueError("the C codec expects big-endian fields and a CRC over header and payload")
    c = fr.checksum
    if c.width != 16:
        raise N.Unsupported(N.of_checksum("width"), "the C codec implements 16-bit checksums only")
    if c.refin != c.refout:
        raise N.Unsupported(N.of_checksum("refout"), "the C codec needs refin == refout")
    poly = int(f"{c.poly:016b}"[::-1], 2) if c.refin else c.poly
    return FrameView(
        dst=fr.header.index("dst"), src=fr.header.index("src"), opcode=fr.header.index("opcode"),
        length=fr.header.index("length"), header_size=fr.header_size, crc_size=fr.crc_size,
        overhead=fr.overhead, max_payload=fr.max_payload, max_frame=spec.max_frame,
        crc_name=c.name, crc_poly=poly, crc_init=c.init, crc_xorout=c.xorout, crc_reflected=c.refin,
        crc_fast_1021=(c.poly == 0x1021 and not c.refin), crc_check=c.check,
    )


def _linear(fv: FieldView, enc: Linear) -> Scaled:
    s, o = enc.scale, enc.offset
    if s <= 0:
        raise N.Unsupported(fv.origin, "the C helpers need a positive scale")
    # to_milli: milli = round_half_away((raw*s + o) * 1000)
    a1, a0 = s * MILLI, o * MILLI
    D = lcm(a1.denominator, a0.denominator)
    A, B = int(a1 * D), int(a0 * D)
    # from_milli: raw = round_half_away((milli/1000 - o) / s)
    c1, c0 = 1 / (s * MILLI), -o / s
    G = lcm(c1.denominator, c0.denominator)
    E, F = int(c1 * G), int(c0 * G)
    # milli interval that encodes into raw_range, found with the reference rule itself
    to_raw = enc.to_raw_milli
    lo = _search(INT32_MIN, INT32_MAX, lambda x: to_raw(x) >= fv.raw_lo)
    hi_first_over = _search(INT32_MIN, INT32_MAX, lambda x: to_raw(x) > fv.raw_hi)
    if lo is None:
        raise N.Unsupported(fv.origin, "no int32 milli value encodes into the raw range (C helpers)")
    hi = INT32_MAX if hi_first_over is None else hi_first_over - 1
    mlo = None if lo == INT32_MIN else lo
    mhi = None if hi == INT32_MAX else hi
    # arithmetic width: every intermediate of the helper must fit
    to_ext = [A * r + B for r in (fv.cmin, fv.cmax)]
    for r in (fv.cmin, fv.cmax):
        milli = enc.to_phys_milli(r)
        if not INT32_MIN <= milli <= INT32_MAX:
            raise N.Unsupported(fv.origin, f"the milli value of raw {r} does not fit the C helpers' int32_t")
    from_ext = [E * x + F for x in (lo, hi)]
    fits = lambda vals, d: all(INT32_MIN < v < INT32_MAX for v in vals) and d < (1 << 30)
    if not all(INT64_MIN < v < INT64_MAX for v in to_ext + from_ext):
        raise N.Unsupported(fv.origin, "scale and offset too extreme for the C helpers' int64_t arithmetic")
    return Scaled(
        kind="linear", to_milli=f"{fv.prefix}_to_milli", from_milli=f"{fv.prefix}_from_milli",
        doc=f"phys = raw * {s} + {o} {fv.unit}".rstrip(),
        A=A, B=B, D=D, E=E, F=F, G=G, mlo=mlo, mhi=mhi,
        to_wide=not fits(to_ext, D), from_wide=not fits(from_ext, G),
    )


def _log10(fv: FieldView, enc: Log10, tables: dict[tuple, Log10Table]) -> Scaled:
    key = (enc.ref, enc.per_decade, enc.raw_max)
    if key not in tables:
        thr, phys = enc.thresholds_milli(), enc.phys_milli_table()
        if any(not INT32_MIN <= v <= INT32_MAX for v in thr + phys):
            raise N.Unsupported(fv.origin, "the logarithmic table does not fit the C helpers' int32_t")
        if thr != sorted(thr):
            raise N.Unsupported(fv.origin, "the logarithmic thresholds are not ascending")
        tables[key] = Log10Table(index=len(tables) + 1, enc=enc, thresholds=thr, phys=phys)
    t = tables[key]
    return Scaled(
        kind="log10", to_milli=f"{fv.prefix}_to_milli", from_milli=f"{fv.prefix}_from_milli",
        doc=f"raw = {enc.per_decade} * log10(phys / {enc.ref}) {fv.unit}, table {t.index}".rstrip(),
        table=t,
        raw_lo_check=fv.raw_lo if fv.raw_lo > 0 else None,
        raw_hi_check=fv.raw_hi if fv.raw_hi < enc.raw_max else None,
    )


def _unique_one(candidates: list[MessageView], what: str, origin: N.Origin) -> MessageView:
    if len(candidates) != 1:
        raise N.Unsupported(origin, f"the C skeleton needs exactly one {what} the role sends, "
                                    f"found {', '.join(m.name for m in candidates) or 'none'}")
    return candidates[0]


def view(spec: Spec) -> dict:
    fr = _frame_view(spec)
    messages = [MessageView(m, fr.overhead, spec) for m in spec.messages]
    by_name = {mv.name: mv for mv in messages}
    tables: dict[tuple, Log10Table] = {}
    for mv in messages:
        for fv in mv.fields:
            enc = fv.f.encoding
            if not fv.f.scaled:
                continue
            if fv.is_array:
                raise N.Unsupported(fv.origin, "scaled arrays are not supported by the C codec")
            fv.scaled = _linear(fv, enc) if isinstance(enc, Linear) else _log10(fv, enc, tables)

    node_addrs = [n.address for n in spec.nodes]
    roles = []
    for role in spec.roles:
        rx = [by_name[m.name] for m in spec.receives(role)]
        nodes = [(n.ident, n.address) for n in spec.role_nodes(role)]
        rv = RoleView(
            role=role, lname=role.lower(), nodes=nodes, receives=rx,
            rx_max=fr.overhead + max([m.max_size for m in rx] or [0]),
            addr_cond=filters.runs_condition("address", filters.runs([a for _, a in nodes])),
        )
        sends = set(m.name for m in spec.sends(role))
        for mv in rx:
            if mv.name == INIT:
                rv.init = mv
            elif mv.name == ID_REQ:
                rv.id_req = mv
                if ID_ACK not in sends:
                    raise N.Unsupported(N.of_role(spec, role), f"receives {ID_REQ} but does not send {ID_ACK} (seed 3.2.2)")
                rv.id_ack = by_name[ID_ACK]
                node_fields = [fv.name for fv in rv.id_ack.fields if fv.kind == "node" and not fv.is_array]
                # the skeleton writes the own address as the payload's one byte (node.c.j2, issue 15)
                if len(rv.id_ack.fields) != 1 or not node_fields or rv.id_ack.fields[0].bits != 8 \
                        or rv.id_ack.fields[0].byte != 0 or rv.id_ack.max_size != 1:
                    raise N.Unsupported(rv.id_ack.origin, "must carry exactly one field, the node address in one byte (seed 3.2.2)")
                rv.id_ack_field = node_fields[0]
            elif mv.name == STATUS_REQ:
                rv.status_req = mv
                # the reply is the spec's reply_to, not a name match (issue 16); the lint allows one per role
                rv.status_ack = _unique_one(
                    [m for m in messages if m.m.reply_to == STATUS_REQ and role in m.senders], STATUS_ACK, N.of_role(spec, role))
                if not rv.status_ack.has_fields:
                    raise N.Unsupported(rv.status_ack.origin, "a STATUS_ACK needs a field for the C skeleton to fill")
            else:
                rv.others.append(mv)
                # seed 3.2.2: a request this role answers (spec reply_to) is answered through the skeleton's reply path
                answer = spec.reply(mv.name, role)
                if answer is not None:
                    rep = by_name[answer.name]
                    if mv.has_fields or not rep.has_fields:
                        raise N.Unsupported(rep.origin, f"the C skeleton answers {mv.name} only as an empty request "
                                                        "with a reply that has fields (its decoded request and reply share node->msg)")
                    rv.replies[mv.name] = rep
        roles.append(rv)

    return {
        "frame": fr,
        "messages": messages,
        "messages_by_opcode": sorted(messages, key=lambda mv: mv.opcode),
        "tables": sorted(tables.values(), key=lambda t: t.index),
        "roles": roles,
        "errors": ERROR_KINDS,
        "nodes": [(n.ident, n.address, n.short, n.role) for n in spec.nodes],
        "node_cond": filters.runs_condition("a", filters.runs(node_addrs)),
        "broadcast_cond": filters.runs_condition("op", filters.runs([m.opcode for m in spec.messages if m.broadcast])),
        "broadcast": spec.broadcast,
        "hash32": spec.hash32,
        "enums": spec.enums,
        "flags": spec.flags,
        "max_union": max(m.max_size for m in messages),
    }


def outputs(spec: Spec) -> list[Output]:
    vm = view(spec)
    out = [
        Output("arachnae.h", "arachnae.h.j2", {"vm": vm}),
        Output("arachnae_frame.c", "arachnae_frame.c.j2", {"vm": vm}),
        Output("arachnae_generic.h", "arachnae_generic.h.j2", {"vm": vm}),
        Output("arachnae_generic.c", "arachnae_generic.c.j2", {"vm": vm}),
    ]
    for mv in vm["messages"]:
        out.append(Output(mv.file, "msg.c.j2", {"vm": vm, "m": mv}))
    for t in vm["tables"]:
        out.append(Output(t.file, "log10.c.j2", {"vm": vm, "t": t}))
    for rv in vm["roles"]:
        out.append(Output(f"node_{rv.lname}.h", "node.h.j2", {"vm": vm, "r": rv}))
        out.append(Output(f"node_{rv.lname}.c", "node.c.j2", {"vm": vm, "r": rv}))
    return out
