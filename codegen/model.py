"""The spec as objects: the one model that codegen, model_check and sim2d read.

`load_spec()` parses spec/nodes.yaml and spec/messages.yaml, checks structure and
meaning (codegen.lint) and only then builds this model, so everything downstream
may assume a consistent network.
"""
from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass, field
from fractions import Fraction
from functools import cached_property
from pathlib import Path
from typing import Any, Iterator

from codegen.encoding import MILLI, Encoding, Linear, Log10, to_fraction

SPEC_DIR = Path(__file__).resolve().parent.parent / "spec"

# The codecs' error kinds, in the order every codec checks them (C and Python share this list).
ERROR_KINDS: tuple[tuple[str, str], ...] = (
    ("OK", "success"),
    ("TRUNCATED", "fewer bytes than header+crc, or than header+length+crc"),
    ("OVERSIZE", "more bytes than the length byte says, or than the parser's buffer holds"),
    ("CHECKSUM", "CRC mismatch"),
    ("ADDRESS", "dst is neither the own address nor broadcast: a frame for another node"),
    ("ROUTE", "src is not a node, dst neither a node nor broadcast, or broadcast on a message the spec does not mark broadcast"),
    ("OPCODE", "unknown opcode (or one the role does not receive)"),
    ("LENGTH", "payload size not valid for the message, or an array count that disagrees with it"),
    ("RANGE", "a field outside its raw range, enum or flags mask, or not a node address"),
    ("BUFFER", "caller's output buffer too small"),
)
SPEC_FILES = ("nodes.yaml", "messages.yaml")


@dataclass(frozen=True)
class Node:
    short: str
    long: str
    address: int
    level: int
    role: str
    bus: str | None          # the bus it is a slave on (None for the MCP)
    masters: str | None      # the bus it is master of
    status: str              # 'required' | 'optional'
    section: str
    leg: int | None = None
    joint: int | None = None
    absent: str | None = None  # a function of the node the toolkit does not implement, and why (spec nodes.absent)

    @property
    def ident(self) -> str:
        """A C/Python identifier: LCP(2) -> LCP_2, JAC(1,3) -> JAC_1_3, APU/SDF -> APU_SDF."""
        return self.short.replace("/", "_").replace("(", "_").replace(",", "_").rstrip(")")

    @property
    def required(self) -> bool:
        return self.status == "required"


@dataclass(frozen=True)
class Bus:
    name: str
    long: str
    level: int
    master: str
    baud: int
    bits_per_char: int
    turnaround_us: float
    idle_gap_chars: float
    response_timeout_ms: float
    id_retries: int
    arbitration: str
    section: str
    slaves: tuple[str, ...] = ()
    request_message: str | None = None   # what a slave sends to ask for the line (None: polled bus)
    priority: tuple[str, ...] = ()       # slaves ranked first in arbitration, in order (rank_order: declared_priority)
    fetch_message: str | None = None     # what the master sends to fetch a served request's record

    @property
    def char_time_us(self) -> float:
        return self.bits_per_char * 1e6 / self.baud

    def frame_time_us(self, frame_bytes: int) -> float:
        """Time on the wire of a frame of `frame_bytes` bytes, without gap or turnaround."""
        return frame_bytes * self.char_time_us

    @property
    def idle_gap_us(self) -> float:
        return self.idle_gap_chars * self.char_time_us

    @property
    def frame_gap_us(self) -> float:
        """Least idle time before any frame may start: the turnaround, and the gap that delimits frames."""
        return max(self.turnaround_us, self.idle_gap_us)


@dataclass(frozen=True)
class Line:
    """A serial line off the RS-485 buses (nodes.yaml `lines`), e.g. the UIC/RCP's RS-232C terminal line (4.1)."""

    name: str
    long: str
    node: str                 # the node whose line it is
    baud: int
    data_bits: int
    parity: str               # 'none' | 'even' | 'odd' | 'mark' | 'space'
    stop_bits: float
    section: str

    @property
    def bits_per_char(self) -> int:
        """Start bit, data bits, parity bit, stop bits (1.5 stop bits count as 2 here)."""
        return 1 + self.data_bits + (self.parity != "none") + math.ceil(self.stop_bits)


@dataclass(frozen=True)
class Checksum:
    name: str
    width: int
    poly: int
    init: int
    refin: bool
    refout: bool
    xorout: int
    check: int

    def compute(self, data: bytes) -> int:
        """Bitwise reference implementation (the catalogue definition, for lint and vectors)."""
        top, mask = 1 << (self.width - 1), (1 << self.width) - 1
        crc = self.init
        for byte in data:
            if self.refin:
                byte = int(f"{byte:08b}"[::-1], 2)
            crc ^= byte << (self.width - 8)
            for _ in range(8):
                crc = ((crc << 1) ^ self.poly) & mask if crc & top else (crc << 1) & mask
        if self.refout:
            crc = int(f"{crc:0{self.width}b}"[::-1], 2)
        return crc ^ self.xorout


@dataclass(frozen=True)
class Frame:
    header: tuple[str, ...]
    max_payload: int
    checksum: Checksum
    section: str
    byte_order: str = "big"
    covers: tuple[str, ...] = ()
    pcap_linktype: int = 147      # LINKTYPE_USER0: what a capture of these frames declares (issue 13)

    @property
    def wtap_user_index(self) -> int:
        """n of LINKTYPE_USERn, i.e. Wireshark's encapsulation USERn."""
        return self.pcap_linktype - 147

    @property
    def header_size(self) -> int:
        return len(self.header)

    @property
    def crc_size(self) -> int:
        return self.checksum.width // 8

    @property
    def overhead(self) -> int:
        return self.header_size + self.crc_size

    @property
    def max_size(self) -> int:
        return self.overhead + self.max_payload


@dataclass(frozen=True)
class Enum:
    name: str
    values: dict[str, int]
    section: str
    texts: dict[str, str] = field(default_factory=dict)
    subset_of: str | None = None      # a part of that enum (GAIT, DIRECTION of MOV_CMD): its codes are declared there


def enum_values_of(messages_doc: dict, name: str) -> dict[str, int]:
    """messages.yaml enum `name`'s values: its own, or for a `subset_of` one its names' values in the parent
    ({} for what does not resolve; codegen.lint reports that)."""
    e = messages_doc["enums"].get(name, {})
    if "values" in e:
        return dict(e["values"])
    parent = messages_doc["enums"].get(e.get("subset_of", ""), {}).get("values", {})
    return {n: parent[n] for n in e.get("names", ()) if n in parent}


@dataclass(frozen=True)
class Flags:
    name: str
    bits: dict[str, int]
    section: str

    @property
    def mask(self) -> int:
        mask = 0
        for bit in self.bits.values():
            mask |= bit
        return mask


@dataclass(frozen=True)
class Field:
    name: str
    type: str                 # uint | int | enum | flags | node | char
    bits: int
    offset_bits: int          # from the start of the payload (fixed part)
    enum: Enum | None = None
    flags: Flags | None = None
    unit: str = ""
    encoding: Encoding = Linear()
    range: tuple[Fraction, Fraction] | None = None   # physical, inclusive
    count: str | None = None  # name of the field holding this array's length
    count_max: int = 0
    origin: str = "seed"
    doc: str = ""
    compared_with: str | None = None   # a threshold compared with that data message's record_values

    @property
    def signed(self) -> bool:
        return self.type == "int"

    @property
    def is_array(self) -> bool:
        return self.count is not None

    @property
    def scaled(self) -> bool:
        return not (isinstance(self.encoding, Linear) and self.encoding.identity)

    @property
    def raw_limits(self) -> tuple[int, int]:
        """What the bits can hold."""
        if self.signed:
            return -(1 << (self.bits - 1)), (1 << (self.bits - 1)) - 1
        return 0, (1 << self.bits) - 1

    @property
    def raw_range(self) -> tuple[int, int]:
        """Valid raw values: the declared range encoded, or the type's own domain."""
        if self.enum is not None:
            return min(self.enum.values.values()), max(self.enum.values.values())
        if self.range is None:
            return self.raw_limits
        lo, hi = (self.encoding.to_raw(v) for v in self.range)
        limit_lo, limit_hi = self.raw_limits
        if isinstance(self.encoding, Log10) and self.encoding.saturate:
            lo, hi = max(lo, limit_lo), min(hi, limit_hi)
        return lo, hi

    @property
    def byte_aligned(self) -> bool:
        return self.offset_bits % 8 == 0 and self.bits % 8 == 0


@dataclass(frozen=True)
class Message:
    name: str
    seed_name: str
    opcode: int
    section: str
    origin: str
    broadcast: bool
    senders: tuple[str, ...]
    receivers: tuple[str, ...]
    doc: str
    fields: tuple[Field, ...]
    relayed_as: str | None = None   # the MCP delivers this record to its target as that message
    record: bool = False            # a slave's record: what it hands its master when fetched (seed 3.2.2)
    reply_to: str | None = None     # the request this message answers (seed 3.2.2: a reply within the response timeout)
    carried_in: str | None = None   # sent as a code inside that message's field, never as a frame of its own
    record_values: tuple[str, ...] = ()   # the fields a record's value byte carries (seed 3.2.2, 6.2)
    record_channel: str | None = None     # the field whose value is a record's channel (else: position in record_values)

    @property
    def fixed_size(self) -> int:
        """Bytes before any array (all of the payload when there is none)."""
        return sum(f.bits for f in self.fields if not f.is_array) // 8

    @property
    def array(self) -> Field | None:
        return next((f for f in self.fields if f.is_array), None)

    @property
    def min_size(self) -> int:
        arr = self.array
        if arr is None:
            return self.fixed_size
        count_field = self.field(arr.count)
        return self.fixed_size + max(0, count_field.raw_range[0])

    @property
    def max_size(self) -> int:
        arr = self.array
        return self.fixed_size + (arr.count_max if arr else 0)

    def field(self, name: str) -> Field:
        return next(f for f in self.fields if f.name == name)


@dataclass(frozen=True)
class Protocol:
    """Timing rules the seed leaves open (nodes.yaml `protocol`)."""

    response_timeout_to: str      # 'first_byte' | 'last_byte'
    master_defer_slots: int
    post_report_timeout_ms: float
    move_retries: int
    setpoint_refresh_ms: float
    section: str


@dataclass(frozen=True)
class Reflex:
    """A fast reaction placed low in the hierarchy (seed 5.2, nodes.yaml `reflexes`)."""

    name: str
    source: str               # the node whose records are reflex records
    actor: str                # the node that reacts when such a record passes through it
    to: str
    message: str
    command: str
    min_interval_ms: float    # the source raises a reflex request at most this often
    section: str
    origin: str


@dataclass(frozen=True)
class Requirement:
    """A performance bound of the seed (nodes.yaml `requirements`)."""

    name: str
    bound_ms: float
    rule: str
    section: str


@dataclass(frozen=True)
class Quorum:
    name: str
    unit_key: str
    unit_roles: tuple[str, ...]
    min_complete: int
    section: str


@dataclass(frozen=True)
class PostRule:
    verdict: str
    when: str                 # the condition, in words (the spec's prose)
    section: str


@dataclass(frozen=True)
class PostRules:
    verdicts: tuple[str, ...]
    inactive_statuses: tuple[str, ...]
    quorums: tuple[Quorum, ...]
    section: str
    rules: tuple[PostRule, ...] = ()


@dataclass
class Spec:
    nodes: tuple[Node, ...]
    buses: dict[str, Bus]
    arbitration: dict[str, dict]
    protocol: Protocol
    post: PostRules
    frame: Frame
    enums: dict[str, Enum]
    flags: dict[str, Flags]
    messages: tuple[Message, ...]
    broadcast: int
    level_bits: int
    sources: tuple[Path, ...]
    hash: str                 # sha256 of the spec files, hex
    reflexes: tuple[Reflex, ...] = ()
    requirements: dict[str, Requirement] = field(default_factory=dict)
    lines: dict[str, Line] = field(default_factory=dict)

    # -- lookups -------------------------------------------------------------
    @cached_property
    def _by_short(self) -> dict[str, Node]:
        return {n.short: n for n in self.nodes}

    @cached_property
    def _by_address(self) -> dict[int, Node]:
        return {n.address: n for n in self.nodes}

    @cached_property
    def _by_name(self) -> dict[str, Message]:
        return {m.name: m for m in self.messages}

    @cached_property
    def _by_opcode(self) -> dict[int, Message]:
        return {m.opcode: m for m in self.messages}

    def node(self, short: str) -> Node:
        return self._by_short[short]

    def node_at(self, address: int) -> Node | None:
        return self._by_address.get(address)

    def message(self, name: str) -> Message:
        return self._by_name[name]

    def message_for(self, opcode: int) -> Message | None:
        return self._by_opcode.get(opcode)

    @property
    def hash32(self) -> int:
        """The first 32 bits of the spec hash: what generated files embed and assert."""
        return int(self.hash[:8], 16)

    @cached_property
    def roles(self) -> tuple[str, ...]:
        seen: dict[str, None] = {}
        for n in self.nodes:
            seen.setdefault(n.role, None)
        return tuple(seen)

    def role_nodes(self, role: str) -> list[Node]:
        return [n for n in self.nodes if n.role == role]

    def receives(self, role: str) -> list[Message]:
        return [m for m in self.messages if role in m.receivers]

    def sends(self, role: str) -> list[Message]:
        return [m for m in self.messages if role in m.senders]

    def requesters(self, bus: str) -> list[Node]:
        """The slaves of `bus` that send its request_message, in arbitration rank order (spec
        arbitration.<rule>.rank_order: declared_priority puts buses.<bus>.priority first)."""
        b = self.buses[bus]
        if b.request_message is None:
            return []
        senders = set(self.message(b.request_message).senders)
        nodes = sorted((n for n in self.nodes if n.bus == bus and n.role in senders), key=lambda n: n.address)
        order = self.arbitration.get(b.arbitration, ARBITRATION_DEFAULTS)["rank_order"]
        if order == "descending_address":
            return nodes[::-1]
        if order == "declared_priority":
            first = [self.node(s) for s in b.priority]
            return first + [n for n in nodes if n.short not in b.priority]
        return nodes

    def records(self, role: str, master_role: str) -> list[Message]:
        """The records (`record: true`) a `role` hands a master of `master_role` when fetched, longest first."""
        return sorted((m for m in self.messages if m.record and role in m.senders and master_role in m.receivers),
                      key=lambda m: -m.max_size)

    def fetched_records(self, bus: str) -> dict[str, list[Message]]:
        """seed 3.2.2: per slave role of `bus` (address order), the records it answers the bus's fetch_message with,
        longest first; empty for a bus without one (polled)."""
        b = self.buses[bus]
        if b.fetch_message is None:
            return {}
        master = self.node(b.master).role
        out: dict[str, list[Message]] = {}
        for n in self.slaves(bus):
            if n.role not in out and self.records(n.role, master):
                out[n.role] = self.records(n.role, master)
        return out

    def reply(self, request: str, role: str) -> Message | None:
        """The message `role` answers `request` with (spec messages.<m>.reply_to; the lint allows one per role)."""
        return next((m for m in self.messages if m.reply_to == request and role in m.senders), None)

    def requirement(self, name: str) -> Requirement | None:
        return self.requirements.get(name)

    def slaves(self, bus: str) -> list[Node]:
        return [n for n in self.nodes if n.bus == bus]

    def shared_bus(self, a: Node, b: Node) -> Bus | None:
        """The bus on which a and b can exchange frames: one of them masters it, the other sits on it."""
        for x, y in ((a, b), (b, a)):
            if x.masters is not None and y.bus == x.masters:
                return self.buses[x.masters]
        return None

    def routes(self, message: Message) -> Iterator[tuple[Node, Node, Bus]]:
        """Every (sender, receiver, bus) the message may travel between (docs/decisions.md D2)."""
        for s in self.nodes:
            if s.role not in message.senders:
                continue
            for r in self.nodes:
                if r.role in message.receivers and r is not s:
                    bus = self.shared_bus(s, r)
                    if bus is not None:
                        yield s, r, bus

    @property
    def max_frame(self) -> int:
        return self.frame.overhead + max(m.max_size for m in self.messages)

    def frame_time_us(self, bus: str, payload_len: int) -> float:
        """Time on the wire for a frame with `payload_len` payload bytes on `bus`."""
        return self.buses[bus].frame_time_us(self.frame.overhead + payload_len)


# -- building -------------------------------------------------------------------
def _fields(raw_fields: list[dict], enums: dict[str, Enum], flags: dict[str, Flags], max_payload: int) -> tuple[Field, ...]:
    out: list[Field] = []
    offset = 0
    fixed_bytes = sum(_bits_of(f) for f in raw_fields if "count" not in f) // 8
    for f in raw_fields:
        bits = _bits_of(f)
        if "log10" in f:
            lg = f["log10"]
            encoding: Encoding = Log10(to_fraction(lg["ref"]), lg["per_decade"], bool(lg.get("saturate", False)), (1 << bits) - 1)
        else:
            encoding = Linear(to_fraction(f.get("scale", 1)), to_fraction(f.get("offset", 0)))
        rng = tuple(to_fraction(v) for v in f["range"]) if "range" in f else None
        count_max = 0
        if "count" in f:
            count_field = next(c for c in raw_fields if c["name"] == f["count"])
            declared = count_field.get("range", [0, 255])[1]
            count_max = min(int(declared), max_payload - fixed_bytes)
        out.append(Field(
            name=f["name"], type=f["type"], bits=bits, offset_bits=offset,
            enum=enums.get(f.get("enum", "")), flags=flags.get(f.get("flags", "")),
            unit=f.get("unit", ""), encoding=encoding, range=rng,  # type: ignore[arg-type]
            count=f.get("count"), count_max=count_max,
            origin=f.get("origin", "seed"), doc=f.get("doc", ""), compared_with=f.get("compared_with"),
        ))
        if "count" not in f:
            offset += bits
    return tuple(out)


def _bits_of(f: dict) -> int:
    return 8 if f["type"] in ("node", "char") else int(f.get("bits", 8))


# What an arbitration rule means when it leaves a parameter out (seed 3.2.2's plain rule: the colliders
# resend, ranks by address, no reflex lead). The one place these defaults live: the runtime
# (behaviours.netconfig), the models (model_check.spec_adapter) and the docs read the filled-in rule.
ARBITRATION_DEFAULTS: dict[str, Any] = {"rank_order": "ascending_address", "backoff_slots": 1,
                                        "backoff_scope": "colliders", "reflex_lead_bits": 0,
                                        "max_collisions_per_request": 0}


def arbitration_rules(doc: dict) -> dict[str, dict]:
    """nodes.yaml `arbitration`, each contention rule with ARBITRATION_DEFAULTS filled in (`polled` has none:
    its slaves never contend)."""
    return {name: dict(rule) if name == "polled" else {**ARBITRATION_DEFAULTS, **rule} for name, rule in doc.items()}


def build(nodes_doc: dict, messages_doc: dict, sources: tuple[Path, ...], digest: str) -> Spec:
    """Build the model from documents that already passed schema and lint."""
    nodes = tuple(
        Node(short=n["short"], long=n["long"], address=n["address"], level=n["level"], role=n["role"],
             bus=n["bus"], masters=n.get("masters"), status=n["status"], section=n["section"],
             leg=n.get("leg"), joint=n.get("joint"), absent=n.get("absent"))
        for n in nodes_doc["nodes"]
    )
    buses = {
        name: Bus(name=name, long=b["long"], level=b["level"], master=b["master"], baud=b["baud"],
                  bits_per_char=b["bits_per_char"], turnaround_us=b["turnaround_us"],
                  idle_gap_chars=b["idle_gap_chars"], response_timeout_ms=b["response_timeout_ms"],
                  id_retries=b["id_retries"], arbitration=b["arbitration"], section=b["section"],
                  slaves=tuple(n.short for n in nodes if n.bus == name), request_message=b.get("request_message"),
                  priority=tuple(b.get("priority", ())), fetch_message=b.get("fetch_message"))
        for name, b in nodes_doc["buses"].items()
    }
    post_doc = nodes_doc["post"]
    post = PostRules(
        verdicts=tuple(post_doc["verdicts"]), inactive_statuses=tuple(post_doc["inactive_statuses"]),
        quorums=tuple(Quorum(q["name"], q["unit_key"], tuple(q["unit_roles"]), q["min_complete"], q["section"])
                      for q in post_doc["quorums"]),
        section=post_doc["section"],
        rules=tuple(PostRule(r["verdict"], r["when"], r["section"]) for r in post_doc["rules"]),
    )
    fdoc = messages_doc["frame"]
    c = fdoc["checksum"]
    frame = Frame(tuple(fdoc["header"]), fdoc["max_payload"],
                  Checksum(c["name"], c["width"], c["poly"], c["init"], c["refin"], c["refout"], c["xorout"], c["check"]),
                  fdoc["section"], byte_order=fdoc["byte_order"], covers=tuple(c["covers"]),
                  pcap_linktype=fdoc["pcap_linktype"])
    enums = {k: Enum(k, enum_values_of(messages_doc, k), v["section"], dict(v.get("texts", {})), v.get("subset_of"))
             for k, v in messages_doc["enums"].items()}
    flags = {k: Flags(k, dict(v["bits"]), v["section"]) for k, v in messages_doc["flags"].items()}
    messages = tuple(
        Message(name=m["name"], seed_name=m.get("seed_name", m["name"]), opcode=m["opcode"], section=m["section"],
                origin=m.get("origin", "seed"), broadcast=bool(m.get("broadcast", False)),
                senders=tuple(m["from"]), receivers=tuple(m["to"]), doc=m["doc"],
                fields=_fields(m.get("fields", []), enums, flags, fdoc["max_payload"]), relayed_as=m.get("relayed_as"),
                record=bool(m.get("record", False)), reply_to=m.get("reply_to"),
                carried_in=m.get("carried_in"), record_values=tuple(m.get("record_values", ())),
                record_channel=m.get("record_channel"))
        for m in messages_doc["messages"]
    )
    p = nodes_doc["protocol"]
    protocol = Protocol(p["response_timeout_to"], p["master_defer_slots"], p["post_report_timeout_ms"],
                        p["move_retries"], p["setpoint_refresh_ms"], p["section"])
    return Spec(nodes=nodes, buses=buses, arbitration=arbitration_rules(nodes_doc["arbitration"]), protocol=protocol, post=post, frame=frame,
                enums=enums, flags=flags, messages=messages, broadcast=nodes_doc["address"]["broadcast"],
                level_bits=nodes_doc["address"]["level_bits"], sources=sources, hash=digest,
                reflexes=tuple(Reflex(r["name"], r["source"], r["actor"], r["to"], r["message"], r["command"],
                                      r["min_interval_ms"], r["section"], r["origin"]) for r in nodes_doc.get("reflexes", [])),
                requirements={q["name"]: Requirement(q["name"], q["bound_ms"], q["rule"], q["section"])
                              for q in nodes_doc.get("requirements", [])},
                lines={k: Line(k, v["long"], v["node"], v["baud"], v["data_bits"], v["parity"], v["stop_bits"], v["section"])
                       for k, v in nodes_doc.get("lines", {}).items()})


def spec_digest(paths: tuple[Path, ...]) -> str:
    h = hashlib.sha256()
    for p in paths:
        h.update(p.name.encode() + b"\0" + p.read_bytes() + b"\0")
    return h.hexdigest()


__all__ = ["ERROR_KINDS", "Spec", "Node", "Bus", "Line", "Message", "Field", "Enum", "Flags", "Frame", "Checksum", "PostRule", "PostRules", "Protocol",
           "Quorum", "Reflex", "Requirement", "SPEC_DIR", "SPEC_FILES", "MILLI", "build", "enum_values_of", "spec_digest"]
