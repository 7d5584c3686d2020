"""Node identification (seed 3.2.2 "Initialisierung"): ID_REQ, timeout, one retry, NODES table.

The master probes its slaves one after another in address order. One tick is
one character time on the bus; frame, timeout and turnaround durations come
from the spec in whole ticks (rounded up). The environment decides, on the
first ID_REQ a node receives, whether it answers at all; every ID_REQ and
every ID_ACK may be lost (a late ACK colliding with the master's next ID_REQ is
covered by that loss). A node that answers does so after any delay up to
`max_delay_ticks`, so an ID_ACK may arrive after the timeout, after the retry
went out, or after the master moved on to the next node -- and a node that
receives both requests answers twice.

Corruption of ID_REQ / ID_ACK is abstracted as loss, and why: a corrupt frame
fails its CRC and is dropped, so to its receiver it is a loss; what differs is
only when the master talks next, which no property here depends on:
- a corrupt ID_ACK: the master waits for it to end (the timeout runs to the
  first byte, protocol.response_timeout_to) and, on a contended bus, for the
  slaves' backoff window the corrupt frame opened (the arbitration model's
  master only listens then), then retries as after a loss;
- a corrupt ID_REQ: the node drops it (a loss to it); the master hears its
  own echo corrupt and sends it again after that window (seed 3.2.2's echo
  rule), without spending its retry. Here the loss spends it, so the model
  declares a node inactive no later than the code does; repeated corruption
  delays the round without bound (the code resends on every corrupt echo), so
  `round_complete`'s tick bound holds for losses, not for a noisy line.
tracecheck checks both on every trace: `id_retry` counts attempts without the
echo resends (a resend after a corrupt echo is none) and demands a resend when
no intact ID_ACK came; `id_timeout` holds the resend to the timeout and, after
a corrupt frame, to the window (`_slaves_window_end`); the POST oracle counts
only intact, timely ID_ACKs. tests/trace/test_mutations.py runs a POST with
the sensor bus corrupting ID frames (0 violations) and a master that takes a
corrupt frame for the ID_ACK (caught by id_retry).
"""
from __future__ import annotations

from model_check.gcl import Event, Invariant, Model, Response, Rule, Var
from model_check.spec_adapter import IdParams

UNKNOWN, ACTIVE, INACTIVE = 0, 1, 2
UNDECIDED, ANSWERS, SILENT = 0, 1, 2


def build(p: IdParams, nodes: int | None = None) -> Model:
    names = p.slaves[:nodes] if nodes else p.slaves
    n = len(names)
    attempts = p.retries + 1
    RQ, T, D, A = p.req_ticks, p.timeout_ticks, p.max_delay_ticks, p.ack_ticks
    window_end = RQ + T                  # seed 3.2.2: no ID_ACK within 10 ms of the request -> resend
    vs = [Var("cur", n, doc="node being probed (n: round over)"), Var("att", attempts - 1),
          Var("tmr", window_end, doc="ticks since the current ID_REQ started"),
          Var("qd", 1, doc="1 once the current ID_REQ is off the wire")]
    for j, name in enumerate(names):
        vs += [Var(f"e{j}", 2, doc=f"NODES[{name}]: 0 unknown, 1 active, 2 inactive"),
               Var(f"c{j}", 2, doc=f"{name}: 0 not yet asked, 1 answers, 2 never answers"),
               Var(f"h{j}", 1, doc=f"monitor: an intact ID_ACK of {name} reached the master while it probed {name}")]
        vs += [Var(f"r{j}_{a}", D + 1, doc=f"{name}: age+1 of its reply to request {a} (0: none)")
               for a in range(attempts)]
    m = p.master
    replies = [f"r{j}_{a}" for j in range(n) for a in range(attempts)]
    next_node = (("cur", "cur + 1"), ("att", "0"), ("tmr", "0"), ("qd", "0"))
    rules: list[Rule] = []
    for j, name in enumerate(names):
        at_req = f"cur == {j} and tmr == {RQ} and qd == 0"
        rules.append(Rule(f"req_lost_{j}", at_req, (("qd", "1"),), actor=None,
                          msc=(Event(m, name, "ID_REQ (lost or corrupted)"),)))
        rules.append(Rule(f"req_ignored_{j}", f"{at_req} and c{j} != {ANSWERS}",
                          ((f"c{j}", str(SILENT)), ("qd", "1")), actor=None,
                          msc=(Event(m, name, "ID_REQ (node never answers)"),)))
        for a in range(attempts):
            rules.append(Rule(f"req_answered_{j}_{a}", f"{at_req} and c{j} != {SILENT} and att == {a}",
                              ((f"c{j}", str(ANSWERS)), (f"r{j}_{a}", "1"), ("qd", "1")), actor=None,
                              msc=(Event(m, name, f"ID_REQ #{a + 1}"),)))
            r = f"r{j}_{a}"
            ready = f"{r} > {A}"          # the ACK needs A ticks on the wire
            rules.append(Rule(f"ack_accepted_{j}_{a}", f"{ready} and cur == {j} and qd == 1",
                              ((r, "0"), (f"e{j}", str(ACTIVE)), (f"h{j}", "1")) + next_node, actor=None,
                              msc=(Event(name, m, f"ID_ACK {name} (answer to #{a + 1}): active"),)))
            rules.append(Rule(f"ack_stale_{j}_{a}", f"{ready} and cur != {j}", ((r, "0"),), actor=None,
                              msc=(Event(name, m, f"ID_ACK {name} (answer to #{a + 1}): late, ignored"),)))
            rules.append(Rule(f"ack_lost_{j}_{a}", ready, ((r, "0"),), actor=None,
                              msc=(Event(name, m, f"ID_ACK {name} (lost or corrupted)"),)))
        rules.append(Rule(f"timeout_inactive_{j}",
                          f"cur == {j} and qd == 1 and tmr == {window_end} and att == {attempts - 1}",
                          ((f"e{j}", str(INACTIVE)),) + next_node, actor="master",
                          msc=(Event(m, None, f"timeout: {name} inactive"),)))
    rules.append(Rule("timeout_retry", f"cur < {n} and qd == 1 and tmr == {window_end} and att < {attempts - 1}",
                      (("att", "att + 1"), ("tmr", "0"), ("qd", "0")), actor="master",
                      msc=(Event(m, None, "timeout: send ID_REQ again"),)))
    urgent = f"(cur < {n} and tmr == {RQ} and qd == 0) or (cur < {n} and tmr == {window_end})"
    pending = " or ".join(f"{r} > 0" for r in replies)
    rules.append(Rule("tick", f"(cur < {n} or {pending}) and not ({urgent}) and "
                      + " and ".join(f"{r} <= {D}" for r in replies),
                      (("tmr", f"tmr + 1 if cur < {n} else tmr"),) + tuple((r, f"{r} + 1 if {r} > 0 else 0")
                                                                          for r in replies),
                      actor="clock", ticks=1))
    invs = []
    for j, name in enumerate(names):
        invs += [
            Invariant(f"active_only_if_answered_{name}", f"e{j} != {ACTIVE} or (h{j} == 1 and c{j} == {ANSWERS})"),
            Invariant(f"answered_is_active_{name}", f"h{j} == 0 or e{j} == {ACTIVE}"),
            Invariant(f"silent_is_inactive_{name}", f"c{j} != {SILENT} or e{j} != {ACTIVE}"),
            Invariant(f"table_in_order_{name}", f"(cur > {j} and e{j} != {UNKNOWN}) or (cur <= {j} and e{j} == {UNKNOWN})"),
        ]
    resp = [Response(f"decided_{name}", f"cur == {j}", f"cur > {j}") for j, name in enumerate(names)]
    resp.append(Response("round_complete", "cur == 0", f"cur == {n}"))
    return Model(name=f"id_retry[{p.bus},{n} nodes]", vars=vs, rules=rules, invariants=invs,
                 final=f"cur == {n} and " + " and ".join(f"{r} == 0" for r in replies),
                 responses=resp, tick_us=p.tick_us, participants=[m] + list(names),
                 notes=[f"seed 3.2.2: timeout {T} ticks, {p.retries} retry; tick = {p.tick_us:.1f} us"])
