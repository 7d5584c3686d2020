"""Worst-case timing from the spec: POST, whisker-to-STOP latency, a full ultrasonic scan.

Frame times come from the spec (frame size at the bus's baud rate plus
the frame gap); the bounds are the spec's `requirements`; whisker to STOP is
the worst case of the timed reaction model, explored over every phase and
contention pattern of the buses on the path. Node processing time is not in the spec and counts as
zero: every figure here is a lower bound on the real worst case in that sense.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

from arachnae.errors import UserError
from model_check import spec_adapter as sa
from model_check.engine import explore
from arachnae.errors import UserError
from model_check.models import reaction

SPEED_OF_SOUND = 343.0          # m/s (issue 3)


@dataclass
class Figure:
    name: str
    ms: float | None
    bound_ms: float | None
    section: str
    parts: list[str] = field(default_factory=list)
    verdict: str = ""


def post_duration(spec) -> Figure:
    """seed 6.3 / 3.2.2: every node needs at most (retries + 1) x (ID_REQ + timeout) on its master's bus."""
    pp = sa.post(spec)
    parts, total = [], 0.0
    for n in pp.nodes:
        if n.master is None:
            continue
        node = spec.node(n.short)
        bus = spec.buses[node.bus]
        per = (bus.id_retries + 1) * (sa.frame_us(spec, bus.name, "ID_REQ") + sa.response_window_us(spec, bus.name))
        total += per
        if n.masters:     # the sub-master's report to its own master
            total += sa.frame_us(spec, bus.name, "POST_QUERY") + sa.frame_us(spec, bus.name, "POST_REPORT")
    parts.append(f"{len(pp.nodes) - 1} nodes identified one after another, each at worst two ID_REQ + timeout "
                 f"windows, plus POST_QUERY/POST_REPORT per sub-master")
    return Figure("POST worst case", total / 1000, None, "6.3", parts, "no bound in the seed")


def _bound(spec, name: str) -> tuple[float | None, str]:
    """A seed bound declared in the spec (nodes.yaml `requirements`), with its section."""
    r = spec.requirement(name)
    return (r.bound_ms, r.section) if r else (None, "")


def stop_latency(spec, scope: str | None = None) -> Figure:
    """seed 5.2: reaction to a tactile stimulus within the spec's bound: the timed model of the reflex path
    (`arachnae check reaction`), explored over every phase and contention pattern of the buses it crosses."""
    bound, section = _bound(spec, "reaction")
    try:
        p = sa.reaction(spec)
    except UserError as exc:
        return Figure("whisker contact to STOP at the legs", None, bound, section or "5.2", [str(exc)],
                      "CANNOT BE SHOWN: no reflex path in the spec")
    res = explore(reaction.build(p), progress=False)
    worst = res.bounds.get("contact_to_legs")
    if not res.ok or worst is None:
        return Figure("whisker contact to STOP at the legs", None, bound, section, ["the reaction model fails"],
                      "CANNOT BE SHOWN: see `arachnae check reaction`")
    ms = worst * res.model.tick_us / 1000
    parts = [f"{h.bus} bus: {h.carrier} -> {h.master} (slot {h.slot_us / 1000:.1f} ms; longest busy period "
             f"{max([h.own_slots, h.carrier_serve_slots] + h.serve_slots)} slots, reflex fetch {h.reflex_slots} slots)"
             for h in p.hops]
    parts.append(f"{p.hops[-1].master} -> {spec.reflexes[0].to}: {p.act_message} {p.act_us / 1000:.1f} ms; "
                 f"then {p.target_slaves} frames on the {p.target_bus} bus after its busy period")
    parts.append(f"proven by `arachnae check reaction` ({res.states} states, every phase and contention pattern)")
    verdict = "meets" if bound is None or ms <= bound else f"FAILS: {ms:.0f} ms > {bound:g} ms"
    return Figure("whisker contact to STOP at the legs", ms, bound, section, parts, verdict)


def scan_duration(spec, measurements: int = 3, step_deg: int = 1, range_m: float = 10.0) -> Figure:
    """seed 3.2.11: 360 deg at 1 deg steps at maximum range within the spec's bound (8 s); three measurements
    per reading (6.2)."""
    steps = math.ceil(360 / step_deg)
    echo = 2 * range_m / SPEED_OF_SOUND
    sonar = sa.receiver_of(spec, "HEAD_STEP")     # seed 3.2.11: the USRC turns the head and measures
    frames_us = sum(sa.frame_us(spec, sonar.bus, m)
                    for m in ("HEAD_STEP", "DO_MEASURE", spec.buses[sonar.bus].fetch_message,  # spec buses.<b>.fetch_message
                              sa.data_record(spec, sonar.role).name))
    per_step = measurements * echo + frames_us / 1e6
    total = steps * per_step
    parts = [f"{steps} steps x ({measurements} x {echo * 1000:.1f} ms echo at {range_m:g} m "
             f"+ {frames_us / 1000:.1f} ms of sensor-bus frames)"]
    bound, section = _bound(spec, "scan")
    limit = (bound or math.inf) / 1000
    verdict = "meets" if total <= limit else f"FAILS: {total:.1f} s > {limit:g} s"
    if total > limit:
        max_steps = math.floor(limit / per_step)
        parts.append(f"sound alone: {steps * measurements * echo:.1f} s; frames alone: {steps * frames_us / 1e6:.1f} s")
        parts.append(f"would meet {limit:g} s with a step of {360 / max(max_steps, 1):.1f} deg ({max_steps} readings)")
        budget = limit / steps - frames_us / 1e6
        if budget > 0:
            parts.append(f"or, at 1 deg, a range of {budget / measurements * SPEED_OF_SOUND / 2:.2f} m")
        else:
            parts.append(f"at 1 deg no range meets it: the frames alone exceed {limit:g} s at this baud rate")
    return Figure("360 deg ultrasonic scan", total * 1000, bound, section or "3.2.11", parts, verdict)


def id_timeout_check(spec) -> list[str]:
    """seed 3.2.2: a reply must be able to start within the timeout after the frame gap that delimits frames."""
    out = []
    first_byte = spec.protocol.response_timeout_to == "first_byte"
    for b in spec.buses.values():
        ack_ms = spec.frame_time_us(b.name, sa.need_message(spec, "ID_ACK").max_size) / 1000
        earliest_ms = b.frame_gap_us / 1000 + (0 if first_byte else ack_ms)
        if earliest_ms > b.response_timeout_ms:
            out.append(f"bus {b.name}: a reply cannot {'start' if first_byte else 'end'} before {earliest_ms:.1f} ms at "
                       f"{b.baud} baud (frame gap {b.frame_gap_us / 1000:.1f} ms), later than the "
                       f"{b.response_timeout_ms:g} ms timeout; a timeout of at least {math.ceil(earliest_ms)} ms would meet it")
    return out


def report(spec, scope: str | None = None) -> tuple[list[Figure], list[str]]:
    figures = [post_duration(spec), stop_latency(spec, scope), scan_duration(spec)]
    for f in figures:   # the spec admits only finite numbers, but a sum of them can still overflow
        if f.ms is not None and not math.isfinite(f.ms):
            raise UserError(f"timing: {f.name} comes out as {f.ms} ms; the spec's bus timings are out of any usable range")
    return figures, id_timeout_check(spec)
