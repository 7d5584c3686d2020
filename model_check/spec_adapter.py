"""The one place where the model checker reads the spec.

Every number a model uses (nodes, ranks, timeouts, retries, frame durations at
the bus's baud rate, quorums) comes through here from codegen.model, so the
models restate nothing about the network. Where the spec does not yet carry a
field the checker needs, the fallback is in a clearly named function below and
listed in `MISSING_FIELDS` so it can be wired to the spec later.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from arachnae.errors import UserError

# Fields the checker would read from the spec if they existed (see report).
MISSING_FIELDS = [
    "buses.<bus>.max_response_delay_ms: how late a node may answer (for late-ACK exploration)",
]


def load(spec_dir: str | None = None):
    try:
        from codegen.load import load_spec
    except ImportError as exc:  # pragma: no cover - the lead's loader is part of the repo
        raise UserError(f"cannot load the spec model: {exc}") from None
    return load_spec(spec_dir)


def need_message(spec, name: str):
    """The spec's message `name`, which the models use by its seed name; a spec that renamed or dropped it
    gets a one-line error naming the file instead of a KeyError deep in a model."""
    try:
        return spec.message(name)
    except KeyError:
        raise UserError(f"{spec.sources[-1]}: the model checker needs message {name!r} (the seed's name for it), "
                        f"which this spec does not declare") from None


def need_bus(spec, name: str):
    """The spec's bus `name` (see need_message)."""
    try:
        return spec.buses[name]
    except KeyError:
        raise UserError(f"{spec.sources[0]}: the model checker needs a bus {name!r}, which this spec does not "
                        f"declare; buses: {', '.join(spec.buses)}") from None


def contended_buses(spec) -> list[str]:
    """The buses whose slaves start frames on their own (every arbitration but `polled`), in spec order: the
    buses the arbitration and id_retry models check by default (seed 3.2.2)."""
    return [name for name, bus in spec.buses.items() if bus.arbitration != "polled"] or [next(iter(spec.buses))]


def receiver_of(spec, message: str):
    """The first node that receives `message` and is a bus slave: where the models find the bus a seed
    message travels on (HEAD_STEP: the USRC on the sensor bus)."""
    roles = need_message(spec, message).receivers
    node = next((n for n in spec.nodes if n.role in roles and n.bus is not None), None)
    if node is None:
        raise UserError(f"{spec.sources[-1]}: message {message!r} goes to no bus slave")
    return node


def data_record(spec, role: str):
    """The record a sensor role answers its master's fetch with (seed 3.2.11: XMIT_DATA in each node's encoding;
    spec messages.<m>.record)."""
    bus = spec.role_nodes(role)[0].bus if spec.role_nodes(role) else None
    records = spec.fetched_records(bus).get(role, []) if bus else []
    if not records:
        raise UserError(f"{spec.sources[-1]}: {role} sends its master no message with `record: true`")
    return records[0]


def frame_us(spec, bus: str, message: str) -> float:
    """Wire time of the longest frame of `message` on `bus`, plus the frame gap before it (spec buses)."""
    m = need_message(spec, message)
    b = need_bus(spec, bus)
    return spec.frame_time_us(bus, m.max_size) + b.frame_gap_us


def first_byte_timeout_us(spec, bus: str) -> float:
    """seed 3.2.2: a reply must begin (first_byte) or be complete (last_byte) this long after the request."""
    return spec.buses[bus].response_timeout_ms * 1000.0


def response_window_us(spec, bus: str) -> float:
    """How long a master waits for a reply: seed 3.2.2's timeout, to the reply's first byte when the
    spec says so (protocol.response_timeout_to), then for the rest of the longest ID_ACK."""
    window = first_byte_timeout_us(spec, bus)
    if spec.protocol.response_timeout_to == "first_byte":
        window += spec.frame_time_us(bus, need_message(spec, "ID_ACK").max_size)
    return window


def slots(duration_us: float, slot_us: float) -> int:
    return max(1, math.ceil(duration_us / slot_us - 1e-9))


# -- arbitration ------------------------------------------------------------------
@dataclass
class ArbSlave:
    short: str
    rank: int
    fetch_slots: int          # grant + record
    deliver_slots: int        # relay to the target (0 when the master is the target)
    target: str
    record: str = "record"    # the message it answers the fetch with (spec `record: true`)


@dataclass
class ArbParams:
    bus: str
    master: str
    request: str
    slot_us: float
    slaves: list[ArbSlave]
    backoff_slots: int
    max_collisions: int
    rule_section: str
    scope: str                # who defers after a collision: 'colliders' or 'all'
    reflex: str | None = None     # the slave whose requests carry reflex records here (spec reflexes), if any
    relay: bool = False           # ... which it relays from a bus below (SPU), rather than raises itself (TPSC)
    reflex_gap_slots: int = 0     # whole slots between two reflex records reaching it (reflexes.min_interval_ms)
    reflex_gap_ms: float = 0.0    # ... the spec's interval itself
    fetch: str | None = None      # what the master fetches a served request's record with (buses.<bus>.fetch_message)


def reflex_carrier(spec, bus: str):
    """(reflex, carrier on `bus`) for the reflex whose path runs over `bus`, or None: the carrier is the
    reflex's source or the master relaying its records up the hierarchy towards the actor (seed 3.2.2, 5.2)."""
    for r in spec.reflexes:
        node = spec.node(r.source)
        while node.short != r.actor and node.bus is not None:
            if node.bus == bus:
                return r, node
            node = spec.node(spec.buses[node.bus].master)
    return None


def request_message(spec, bus: str) -> str:
    """The message a slave sends to ask for the bus (spec buses.<bus>.request_message)."""
    name = spec.buses[bus].request_message
    if name is None:
        raise UserError(f"bus {bus}: no request_message in the spec, so its slaves cannot ask for the line")
    return name


def record_route(spec, bus: str, slave) -> tuple[list[str], list[str], str]:
    """Adapter: frames fetching a slave's record and relaying it, and the record's target node.

    seed 3.2.2: the master fetches with the bus's fetch_message; the slave's longest record (spec
    `record: true`) answers; a record with `relayed_as` goes on to the node of the bus that receives that."""
    b = spec.buses[bus]
    master = spec.node(b.master)
    fetch, relay, target = [], [], master.short
    if b.fetch_message is not None:
        fetch.append(b.fetch_message)
    records = spec.records(slave.role, master.role)
    if not records:
        raise UserError(f"{spec.sources[-1]}: {slave.role} sends {master.short} no message with `record: true`")
    record = records[0]
    fetch.append(record.name)
    if record.relayed_as is not None:         # spec messages.<record>.relayed_as
        relayed = spec.message(record.relayed_as)
        dest = next((n for n in spec.nodes if n.bus == bus and n.role in relayed.receivers), None)
        if dest is not None:
            relay.append(relayed.name)
            target = dest.short
    return fetch, relay, target


def arbitration(spec, bus: str, scope: str | None = None) -> ArbParams:
    if bus not in spec.buses:
        raise UserError(f"unknown bus {bus!r}; buses: {', '.join(spec.buses)}")
    b = spec.buses[bus]
    if b.arbitration == "polled":
        raise UserError(f"bus {bus} is polled by its master; slaves never contend (spec buses.{bus}.arbitration)")
    req = request_message(spec, bus)
    nodes = spec.requesters(bus)              # spec arbitration.rank_order (declared_priority: buses.<bus>.priority)
    rule = spec.arbitration[b.arbitration]
    slot_us = frame_us(spec, bus, req)        # spec arbitration.slot: request_frame (+ turnaround)
    slaves = []
    for rank, n in enumerate(nodes):
        fetch, relay, target = record_route(spec, bus, n)
        slaves.append(ArbSlave(n.short, rank, slots(sum(frame_us(spec, bus, f) for f in fetch), slot_us),
                               slots(sum(frame_us(spec, bus, f) for f in relay), slot_us) if relay else 0, target,
                               record=fetch[-1]))
    p = ArbParams(bus=bus, master=b.master, request=req, slot_us=slot_us, slaves=slaves, fetch=b.fetch_message,
                  backoff_slots=int(rule["backoff_slots"]), max_collisions=int(rule["max_collisions_per_request"]),
                  rule_section=rule.get("section", "3.2.2"), scope=scope or rule["backoff_scope"])
    found = reflex_carrier(spec, bus)
    if found is not None and int(rule.get("reflex_lead_bits", 0)) > 0:
        # spec arbitration.reflex_lead_bits: the carrier's reflex request starts first on an idle line;
        # reflexes.min_interval_ms: the source raises one at most this often, so they reach a slot apart
        r, node = found
        p.reflex, p.relay = node.short, node.short != r.source
        p.reflex_gap_ms = float(r.min_interval_ms)
        p.reflex_gap_slots = int(math.floor(r.min_interval_ms * 1000.0 / slot_us + 1e-9))
    return p


# -- identification -------------------------------------------------------------------
@dataclass
class IdParams:
    bus: str
    master: str
    slaves: list[str]
    tick_us: float            # one character time on the bus
    req_ticks: int            # ID_REQ on the wire, with turnaround
    ack_ticks: int            # ID_ACK on the wire, with turnaround
    timeout_ticks: int
    retries: int
    max_delay_ticks: int      # how late a node may answer


def max_response_delay_ticks(spec, bus: str, timeout_ticks: int, req_ticks: int) -> int:
    """Adapter: the spec has no max response delay; explore answers late enough to miss both windows."""
    return (spec.buses[bus].id_retries + 1) * (timeout_ticks + req_ticks + 1)


def identification(spec, bus: str) -> IdParams:
    if bus not in spec.buses:
        raise UserError(f"unknown bus {bus!r}; buses: {', '.join(spec.buses)}")
    b = spec.buses[bus]
    tick = b.char_time_us
    req = slots(frame_us(spec, bus, "ID_REQ"), tick)
    ack = slots(frame_us(spec, bus, "ID_ACK"), tick)
    timeout = slots(response_window_us(spec, bus), tick)    # seed 3.2.2: 10 ms (to the first byte)
    return IdParams(bus=bus, master=b.master, slaves=list(b.slaves), tick_us=tick, req_ticks=req, ack_ticks=ack,
                    timeout_ticks=timeout, retries=b.id_retries,
                    max_delay_ticks=max_response_delay_ticks(spec, bus, timeout, req))


# -- POST ------------------------------------------------------------------------------
@dataclass
class PostNode:
    short: str
    required: bool
    master: str | None        # the node whose bus it sits on
    masters: bool             # is it itself a bus master
    leg: int | None
    joint: int | None


@dataclass
class PostParams:
    nodes: list[PostNode]     # the MCP first, then in hierarchy order
    root: str
    quorums: list[tuple[str, str, int, tuple[str, ...]]]    # (name, unit_key, min_complete, roles)
    inactive_statuses: tuple[str, ...]
    verdicts: tuple[str, ...]
    roles: dict[str, str]


def post(spec) -> PostParams:
    root = next(n for n in spec.nodes if n.bus is None)
    master_of = {b.name: b.master for b in spec.buses.values()}
    nodes = [PostNode(n.short, n.required, master_of[n.bus] if n.bus else None, n.masters is not None,
                      n.leg, n.joint) for n in spec.nodes]
    if set(spec.post.verdicts) != {"OPERATIONAL", "DEGRADED", "HALTED"}:
        raise UserError(f"POST verdicts {spec.post.verdicts} are not OPERATIONAL/DEGRADED/HALTED")
    return PostParams(nodes=nodes, root=root.short,
                      quorums=[(q.name, q.unit_key, q.min_complete, q.unit_roles) for q in spec.post.quorums],
                      inactive_statuses=spec.post.inactive_statuses, verdicts=spec.post.verdicts,
                      roles={n.short: n.role for n in spec.nodes})


# -- reaction (seed 5.2): the reflex path end to end ------------------------------------
@dataclass
class ReflexHop:
    """One slave-initiated hop of the reflex path: `carrier` asks `bus`'s master for the line."""

    bus: str
    master: str
    carrier: str              # the slave whose request carries the reflex record
    slot_us: float            # one request slot (spec arbitration.slot: request_frame)
    others: list[ArbSlave]    # every other requesting slave, in rank order
    serve_slots: list[int]    # slots one service of each other slave takes (defer + fetch + relay)
    carrier_serve_slots: int  # a service of the carrier's ordinary record in progress
    own_slots: int            # the master's longest own transaction, retries included
    reflex_slots: int         # defer + fetch of the reflex record
    queue_ahead: int          # requests the master may already hold ahead of the reflex one


@dataclass
class ReactionParams:
    reflex: str
    section: str
    hops: list[ReflexHop]     # sensor bus, then first-level bus
    act_us: float             # the actor's command to the target: defer + frame
    act_message: str
    target_bus: str           # the bus the target masters (the legs)
    target_slot_us: float
    target_own_slots: int     # the target's longest own transaction in progress
    target_out_us: float      # the command's frames to every slave of the target's bus
    target_slaves: int
    bound_ms: float | None
    bound_section: str


def empty_slot_us(spec, bus: str) -> float:
    """A frame without payload plus the frame gap: the slot a master defers by (protocol.master_defer_slots)."""
    return spec.frame_time_us(bus, 0) + spec.buses[bus].frame_gap_us


def defer_us(spec, bus: str) -> float:
    return spec.protocol.master_defer_slots * empty_slot_us(spec, bus)


def reply_slack_us(spec, bus: str) -> float:
    """A reply may start as late as the response timeout, not just after the frame gap (seed 3.2.2)."""
    b = spec.buses[bus]
    return max(0.0, b.response_timeout_ms * 1000.0 - b.frame_gap_us)


def exchange_us(spec, bus: str, frames: list[str]) -> float:
    """A master's exchange on `bus`: its defer, then the frames (each a request or the reply to the one before)."""
    replies = len(frames) - 1
    return defer_us(spec, bus) + sum(frame_us(spec, bus, f) for f in frames) + replies * reply_slack_us(spec, bus)


# Messages of POST only (seed 6.3): the reaction bound is one of operation, after POST.
POST_ONLY = ("ID_REQ", "ID_ACK", "POST_QUERY", "POST_REPORT")


def own_transaction_us(spec, bus: str) -> float:
    """The longest transaction a master starts on its own on `bus` in operation: the longer of its longest
    frame (sent once: a frame with a payload is an order, not a question, in every table of the seed) and a
    question without payload answered by the longest reply within the response window, (retries + 1) times
    (seed 3.2.2: one retry)."""
    b = spec.buses[bus]
    mrole = spec.node(b.master).role
    sroles = {spec.node(s).role for s in b.slaves}
    out = max(m.max_size for m in spec.messages
              if mrole in m.senders and sroles & set(m.receivers) and m.name not in POST_ONLY)
    back = max(m.max_size for m in spec.messages
               if sroles & set(m.senders) and mrole in m.receivers and m.name not in POST_ONLY)
    order = defer_us(spec, bus) + spec.frame_time_us(bus, out)
    question = (defer_us(spec, bus) + spec.frame_time_us(bus, 0) + b.frame_gap_us
                + b.response_timeout_ms * 1000.0 + spec.frame_time_us(bus, back))
    return max(order, (b.id_retries + 1) * question)


def reflex_hop(spec, bus: str, carrier: str) -> ReflexHop:
    p = arbitration(spec, bus)
    slot = p.slot_us
    others = [s for s in p.slaves if s.short != carrier]
    mine = next((s for s in p.slaves if s.short == carrier), None)
    if mine is None:
        raise UserError(f"bus {bus}: {carrier} sends no {p.request}, so it cannot carry the reflex")
    fetch = {s.short: record_route(spec, bus, spec.node(s.short)) for s in p.slaves}

    def service(short: str) -> int:
        f, relay, _target = fetch[short]
        return slots(exchange_us(spec, bus, f) + sum(frame_us(spec, bus, r) for r in relay), slot)
    return ReflexHop(bus=bus, master=p.master, carrier=carrier, slot_us=slot, others=others,
                     serve_slots=[service(s.short) for s in others], carrier_serve_slots=service(carrier),
                     own_slots=slots(own_transaction_us(spec, bus), slot),
                     reflex_slots=slots(exchange_us(spec, bus, fetch[carrier][0]), slot),
                     # the master serves the requests it holds in rank order: the carrier ranks first
                     queue_ahead=p.slaves.index(mine))


def reaction(spec, name: str | None = None) -> ReactionParams:
    """The reflex path of seed 5.2 from the spec: source -> its bus master -> ... -> actor -> target -> its slaves."""
    if not spec.reflexes:
        raise UserError("spec: no `reflexes` declared, so no reflex path to check (seed 5.2)")
    r = next((x for x in spec.reflexes if name in (None, x.name)), None)
    if r is None:
        raise UserError(f"unknown reflex {name!r}; reflexes: {', '.join(x.name for x in spec.reflexes)}")
    hops, node = [], spec.node(r.source)
    while node.short != r.actor:                 # up the hierarchy: every record runs through the masters (3.2.2)
        if node.bus is None:
            raise UserError(f"reflex {r.name}: {r.actor} is not above {r.source} in the bus hierarchy")
        hops.append(reflex_hop(spec, node.bus, node.short))
        node = spec.node(spec.buses[node.bus].master)
    target = spec.node(r.to)
    tbus = target.masters
    if tbus is None:
        raise UserError(f"reflex {r.name}: {r.to} masters no bus, so its command reaches no actuator")
    act_bus = target.bus
    leg_slaves = spec.slaves(tbus)
    out_msg = max((m for m in spec.messages if target.role in m.senders
                   and {n.role for n in leg_slaves} & set(m.receivers) and m.origin == "extension"),
                  key=lambda m: m.max_size)
    tslot = empty_slot_us(spec, tbus)
    req = spec.requirement("reaction")
    return ReactionParams(
        reflex=r.name, section=r.section, hops=hops,
        act_us=defer_us(spec, act_bus) + frame_us(spec, act_bus, r.message), act_message=r.message,
        target_bus=tbus, target_slot_us=tslot, target_own_slots=slots(own_transaction_us(spec, tbus), tslot),
        target_out_us=len(leg_slaves) * (defer_us(spec, tbus) + frame_us(spec, tbus, out_msg.name)),
        target_slaves=len(leg_slaves), bound_ms=req.bound_ms if req else None,
        bound_section=req.section if req else r.section)
