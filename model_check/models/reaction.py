"""Whisker contact to STOP at the legs (seed 5.2) as one timed guarded-command model of the reflex path.

The path comes from the spec (model_check.spec_adapter.reaction): the reflex's
source asks its bus master for the line (TPSC: DATA_RDY on the sensor bus),
the master fetches the record, hands it up as its own request on the next bus
(SPU: XMIT_REQ on the first-level bus) until it reaches the reflex's actor (the
MCP), which sends the command (MOVE_RELAYED STOP) to the target (the MMC), whose
frames then reach every slave of its own bus (LEG_TARGET to the six LCPs).

Each slave-initiated hop is explored over every phase of its bus when the
record arrives: idle, the master in any slot of its longest own transaction
(retries included), or serving any other slave (or the carrier's own earlier
record) in any slot of that service; every subset of the other slaves with a
request pending, and any of them requesting later. Time is discrete in the
bus's request slot; a tick is weighted by the slot's duration in microseconds,
so the response bound is the worst case in time. One extra slot per hop
covers a record arriving inside a slot.

What the spec's rules make of it (arbitration.address_backoff with a reflex):
a reflex request starts first in any idle stretch (the other requests wait
reflex_lead_bits longer and defer to its carrier), so it waits only for the
busy period under way; once, a request that had already deferred may start
with it and collide (every collider then backs off by rank, the carrier is
rank 0 and goes first in the window). The master then serves the requests it
already holds in rank order (queue_ahead of them before the carrier).

Abstracted away, and why: node processing time (not in the spec; the
simulator measures it); POST traffic (the bound is one of operation); a
contact sooner than reflexes.min_interval_ms after the last reflex request
(the TPSC latches it, and the STOP of that request is already on its way).
"""
from __future__ import annotations

import math

from model_check.gcl import Event, Invariant, Model, Response, Rule, Var
from model_check.spec_adapter import ReactionParams, ReflexHop

IDLE, SERVE, OWN, REFLEX = 0, 1, 2, 3          # master phase


def _us(x: float) -> int:
    return int(math.ceil(x - 1e-6))


def build(p: ReactionParams, others: int | None = None, clock: bool = False) -> Model:
    """The model; `others` keeps only that many other slaves per bus, `clock` adds an elapsed-time variable
    (microseconds, capped just above the bound) and the bound as an invariant, for SPIN to check too."""
    hops = p.hops
    k = max(len(h.others[:others] if others is not None else h.others) for h in hops)
    maxrem = max([p.target_own_slots] + [max(h.own_slots, h.carrier_serve_slots, max(h.serve_slots, default=0),
                                             h.reflex_slots + h.queue_ahead * max(h.serve_slots, default=0))
                                         for h in hops])
    # stages: per hop PICK, ALIGN, RUN; then ACT; then the target's bus PICK, RUN; then DONE
    pick = [3 * i for i in range(len(hops))]
    act = 3 * len(hops)
    tpick, trun, done = act + 1, act + 2, act + 3
    bound_us = _us(p.bound_ms * 1000) if p.bound_ms is not None else None
    cap = (bound_us + 1) if bound_us is not None else 0
    vs = [Var("st", done, doc="stage of the path"), Var("pk", k + 2, doc="which phase variable is chosen next"),
          Var("m", 3, doc="master: 0 listening, 1 serving a slave, 2 its own transaction, 3 serving the reflex"),
          Var("rem", maxrem, doc="slots left of what the master does"), Var("src", k, doc="slave being served"),
          Var("q", max(h.queue_ahead for h in hops) or 1, doc="requests the master holds ahead of the reflex"),
          Var("col", 1, doc="the reflex request collided once"), Var("r", 1, doc="the reflex request got through")]
    vs += [Var(f"ph{j}", 2, doc=f"other slave {j}: 0 idle, 1 request pending, 2 being served") for j in range(k)]
    if clock:
        vs.append(Var("clk", cap, doc="microseconds since the contact (capped)"))
    reset = (("m", "0"), ("rem", "0"), ("src", "0"), ("q", "0"), ("col", "0"), ("r", "0"), ("pk", "0")) + tuple(
        (f"ph{j}", "0") for j in range(k))
    rules: list[Rule] = []

    def timed(name: str, guard: str, effect: tuple, us: int, actor: str, msc: tuple = ()) -> Rule:
        if clock:
            effect = effect + (("clk", f"min(clk + {us}, {cap})"),)
        return Rule(name, guard, effect, actor=actor, ticks=us, msc=msc)

    for i, h in enumerate(hops):
        b, st0 = h.bus, pick[i]
        oth = h.others[:others] if others is not None else h.others
        n = len(oth)
        slot = _us(h.slot_us)
        # -- the phase the bus is in when the record arrives (0 ticks, before or at the hand-off) --
        at = f"st == {st0} and pk == 0"
        rules.append(Rule(f"{b}_phase_idle", at, (("pk", "1"),)))
        for left in range(1, h.own_slots + 1):
            rules.append(Rule(f"{b}_phase_own_{left}", at, (("m", str(OWN)), ("rem", str(left)), ("pk", "1"))))
        for left in range(1, h.carrier_serve_slots + 1):   # the carrier's own earlier record: src n (no ph)
            rules.append(Rule(f"{b}_phase_carrier_{left}", at,
                              (("m", str(SERVE)), ("src", str(n)), ("rem", str(left)), ("pk", "1"))))
        for j, s in enumerate(oth):
            for left in range(1, h.serve_slots[j] + 1):
                rules.append(Rule(f"{b}_phase_serve_{j}_{left}", at, (("m", str(SERVE)), ("src", str(j)),
                                                                      (f"ph{j}", "2"), ("rem", str(left)), ("pk", "1"))))
        for j, s in enumerate(oth):
            here = f"st == {st0} and pk == {j + 1}"
            rules.append(Rule(f"{b}_phase_{j}_quiet", here, (("pk", str(j + 2)),)))
            rules.append(Rule(f"{b}_phase_{j}_pending", f"{here} and ph{j} == 0", ((f"ph{j}", "1"), ("pk", str(j + 2)))))
        for v in range(h.queue_ahead + 1):
            rules.append(Rule(f"{b}_phase_queue_{v}", f"st == {st0} and pk == {n + 1}",
                              (("q", str(v)), ("pk", "0"), ("st", str(st0 + 1)))))
        # -- the record arrives somewhere inside a slot: the request can start at the next slot at the earliest --
        rules.append(timed(f"{b}_align", f"st == {st0 + 1}", (("st", str(st0 + 2)),), slot, b,
                           (Event(h.carrier, None, "reflex record ready"),)))
        run = f"(st == {st0 + 1} or st == {st0 + 2})"
        for j, s in enumerate(oth):          # other slaves' requests come at any time (environment)
            rules.append(Rule(f"{b}_arrive_{j}", f"{run} and ph{j} == 0", ((f"ph{j}", "1"),),
                              msc=(Event(s.short, None, "record pending"),)))
        go = f"st == {st0 + 2}"
        pending = " or ".join(f"ph{j} == 1" for j in range(n)) or "False"
        rules.append(timed(f"{b}_busy", f"{go} and m != {IDLE} and rem > 1", (("rem", "rem - 1"),), slot, b))
        rules.append(timed(f"{b}_own_done", f"{go} and m == {OWN} and rem == 1", (("m", "0"), ("rem", "0")), slot, b))
        for j in range(n + 1):
            eff = (("m", "0"), ("rem", "0"), ("src", "0")) + (((f"ph{j}", "0"),) if j < n else ())
            rules.append(timed(f"{b}_served_{j}", f"{go} and m == {SERVE} and src == {j} and rem == 1", eff, slot, b))
        # seed 5.2 / spec reflexes: the reflex request starts first in the idle stretch
        serve_q = max(h.serve_slots[:n], default=0)
        rules.append(timed(f"{b}_reflex_request", f"{go} and m == {IDLE} and r == 0",
                           (("m", str(REFLEX)), ("rem", f"q * {serve_q} + {h.reflex_slots}"), ("r", "1"), ("q", "0")),
                           slot, b, (Event(h.carrier, h.master, "request (reflex, first in the idle stretch)"),)))
        rules.append(timed(f"{b}_reflex_collision", f"{go} and m == {IDLE} and r == 0 and col == 0 and ({pending})",
                           (("col", "1"),), slot, b,
                           (Event(h.carrier, h.master, "request collides with one that had deferred"),)))
        rules.append(timed(f"{b}_reflex_fetched", f"{go} and m == {REFLEX} and rem == 1",
                           (("st", str(st0 + 3)),) + reset, slot, b,
                           (Event(h.master, h.carrier, "grant / fetch"), Event(h.carrier, h.master, "reflex record"))))
    rules.append(timed("act", f"st == {act}", (("st", str(tpick)),), _us(p.act_us), "act",
                       (Event(hops[-1].master, None, f"{p.act_message} (reflex) sent first"),)))
    for left in range(p.target_own_slots + 1):
        rules.append(Rule(f"{p.target_bus}_phase_{left}", f"st == {tpick}", (("rem", str(left)), ("st", str(trun)))))
    rules.append(timed(f"{p.target_bus}_busy", f"st == {trun} and rem > 0", (("rem", "rem - 1"),),
                       _us(p.target_slot_us), p.target_bus))
    rules.append(timed(f"{p.target_bus}_out", f"st == {trun} and rem == 0", (("st", str(done)),),
                       _us(p.target_out_us), p.target_bus,
                       (Event(p.target_bus, None, f"command to all {p.target_slaves} slaves"),)))
    invs = [Invariant("reflex_served_alone", f"m != {REFLEX} or r == 1"),
            Invariant("one_collision_at_most", "col <= 1")]
    if clock and bound_us is not None:
        invs.append(Invariant("within_bound", f"clk <= {bound_us}", doc=f"seed {p.bound_section}: {p.bound_ms:g} ms"))
    return Model(name=f"reaction[{p.reflex}]", vars=vs, rules=rules, invariants=invs, final=f"st == {done}",
                 responses=[Response("contact_to_legs", "st >= 1", f"st == {done}",
                                     doc=f"seed {p.section}: the command reaches every slave of the target's bus")],
                 tick_us=1.0, bound_ms=p.bound_ms, bound_section=p.bound_section, participants=[h.carrier for h in hops] + [hops[-1].master, p.target_bus],
                 notes=[f"seed {p.section}; hops: " + ", ".join(f"{h.bus} (slot {h.slot_us:.0f} us)" for h in hops)
                        + f"; bound {p.bound_ms:g} ms (seed {p.bound_section})" if p.bound_ms else ""])
