"""Worst-case timing from the spec: POST, whisker-to-STOP latency, a full ultrasonic scan.

Frame times come from the spec (frame size at the bus's baud rate plus
turnaround); contention waits on the slave-initiated buses are the response
bounds K our checker proves for the arbitration model, so the figures hold
for every interleaving. Node processing time is not in the spec and counts as
zero: every figure here is a lower bound on the real worst case in that sense.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

from model_check import spec_adapter as sa
from model_check.engine import explore
from model_check.models import arbitration

SPEED_OF_SOUND = 343.0          # m/s (issue 3)


@dataclass
class Figure:
    name: str
    ms: float | None
    bound_ms: float | None
    section: str
    parts: list[str] = field(default_factory=list)
    verdict: str = ""


def _arb_bound(spec, bus: str, scope: str | None) -> tuple[dict[str, int] | None, float]:
    p = sa.arbitration(spec, bus, scope)
    res = explore(arbitration.build(p, "spec"), progress=False)
    if not res.ok or any(b is None for b in res.bounds.values()):
        return None, p.slot_us
    return {k.removeprefix("served_"): v for k, v in res.bounds.items()}, p.slot_us


def post_duration(spec) -> Figure:
    """seed 6.3 / 3.2.2: every node needs at most (retries + 1) x (ID_REQ + timeout) on its master's bus."""
    pp = sa.post(spec)
    parts, total = [], 0.0
    for n in pp.nodes:
        if n.master is None:
            continue
        node = spec.node(n.short)
        bus = spec.buses[node.bus]
        per = (bus.id_retries + 1) * (sa.frame_us(spec, bus.name, "ID_REQ") + bus.response_timeout_ms * 1000)
        total += per
        if n.masters:     # the sub-master's report to its own master
            total += sa.frame_us(spec, bus.name, "POST_QUERY") + sa.frame_us(spec, bus.name, "POST_REPORT")
    parts.append(f"{len(pp.nodes) - 1} nodes identified one after another, each at worst two ID_REQ + timeout "
                 f"windows, plus POST_QUERY/POST_REPORT per sub-master")
    return Figure("POST worst case", total / 1000, None, "6.3", parts, "no bound in the seed")


def stop_latency(spec, scope: str | None) -> Figure:
    """seed 5.2: reaction to a tactile stimulus within 1 s; path TPSC-SPU-MCP-NP3-MCP-MMC-LCPs."""
    parts, total = [], 0.0
    sensor, s_slot = _arb_bound(spec, "sensor", scope)
    first, f_slot = _arb_bound(spec, "first", scope)
    if sensor is None or first is None:
        return Figure("whisker to STOP", None, 1000.0, "5.2",
                      ["the arbitration rule as declared has no response bound (see `arachnae check arbitration`)"],
                      "CANNOT BE SHOWN: arbitration unbounded; with backoff_scope: all it is bounded")
    hops = [("TPSC -> SPU (contention + fetch)", sensor["TPSC"] * s_slot),
            ("SPU -> MCP -> NP3 (contention + fetch + DATA)", first["SPU"] * f_slot),
            ("NP3 -> MCP -> MMC (contention + MOVE + MOVE_RELAYED)", first["NP3"] * f_slot)]
    legs = [n for n in spec.nodes if n.bus == "leg"]
    leg_us = (sa.frame_us(spec, "leg", "LEG_POLL") + sa.frame_us(spec, "leg", "LEG_REPORT")
              + len(legs) * sa.frame_us(spec, "leg", "LEG_TARGET"))
    hops.append((f"MMC -> {len(legs)} LCPs (finish a poll, then LEG_TARGET each)", leg_us))
    for name, us in hops:
        total += us
        parts.append(f"{name}: {us / 1000:.1f} ms")
    ms = total / 1000
    verdict = "meets" if ms <= 1000 else f"FAILS: {ms:.0f} ms > 1000 ms"
    return Figure("whisker contact to STOP at the legs", ms, 1000.0, "5.2", parts, verdict)


def scan_duration(spec, measurements: int = 3, step_deg: int = 1, range_m: float = 10.0) -> Figure:
    """seed 3.2.11: 360 deg at 1 deg steps at maximum range within 8 s; three measurements per reading (6.2)."""
    steps = math.ceil(360 / step_deg)
    echo = 2 * range_m / SPEED_OF_SOUND
    frames_us = sum(sa.frame_us(spec, "sensor", m) for m in ("HEAD_STEP", "DO_MEASURE", "XMIT_DATA", "XMIT_DATA_USRC"))
    per_step = measurements * echo + frames_us / 1e6
    total = steps * per_step
    parts = [f"{steps} steps x ({measurements} x {echo * 1000:.1f} ms echo at {range_m:g} m "
             f"+ {frames_us / 1000:.1f} ms of sensor-bus frames)"]
    verdict = "meets" if total <= 8 else f"FAILS: {total:.1f} s > 8 s"
    if total > 8:
        max_steps = math.floor(8 / per_step)
        parts.append(f"sound alone: {steps * measurements * echo:.1f} s; frames alone: {steps * frames_us / 1e6:.1f} s")
        parts.append(f"would meet 8 s with a step of {360 / max(max_steps, 1):.1f} deg ({max_steps} readings)")
        budget = 8 / steps - frames_us / 1e6
        if budget > 0:
            parts.append(f"or, at 1 deg, a range of {budget / measurements * SPEED_OF_SOUND / 2:.2f} m")
        else:
            parts.append("at 1 deg no range meets it: the frames alone exceed 8 s at this baud rate")
    return Figure("360 deg ultrasonic scan", total * 1000, 8000.0, "3.2.11", parts, verdict)


def id_timeout_check(spec) -> list[str]:
    """seed 3.2.2: an ID_ACK must fit in the 10 ms window, or no node can answer the retry in time."""
    out = []
    for b in spec.buses.values():
        ack = sa.frame_us(spec, b.name, "ID_ACK") / 1000
        if ack > b.response_timeout_ms:
            out.append(f"bus {b.name}: ID_ACK takes {ack:.1f} ms on the wire at {b.baud} baud, longer than the "
                       f"{b.response_timeout_ms:g} ms timeout; a timeout of at least {math.ceil(ack)} ms "
                       f"(or {math.ceil(7 * 10 * 1000 / b.response_timeout_ms)} baud) would meet it")
    return out


def report(spec, scope: str | None = None) -> tuple[list[Figure], list[str]]:
    return [post_duration(spec), stop_latency(spec, scope), scan_duration(spec)], id_timeout_check(spec)
