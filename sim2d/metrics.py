"""Metrics of a finished run and the scenario's expectations checked against them."""
from __future__ import annotations

import functools
import hashlib
import math
import types
from bisect import bisect_left
from typing import TYPE_CHECKING, Any, Sequence, Union, get_args, get_origin, get_type_hints, is_typeddict

from behaviours import ROLES
from sim2d.gait_metrics import motion_schema
from sim2d.nav_metrics import nav_schema

from tracecheck.trace import COLUMNS, parse_lines
from tracecheck.validate import validate

if TYPE_CHECKING:
    from sim2d.robot import Robot
    from sim2d.sim import Simulation, TraceEntry


def reactions(stimuli: list[tuple[float, str]], moves: list[tuple[float, int]],
              busy: Sequence[tuple[float, float]] = (), ready: float | None = 0.0,
              end: float | None = None) -> list[dict[str, Any]]:
    """seed 5.2: for each stimulus the robot could act on, the time until its reaction reaches the MMC.

    One record per counted stimulus: stimulus_s (after `ready`), kind, move_s (the reaction; the run's end
    when it never came), latency_s and answered (False: the run ended first).

    Definitions (all times in simulated seconds):
      - a stimulus is what a sensor notes as new: a whisker contact that changes (TPSC) or an object
        entering the IR near zone (IRRC, tuning.IRRC_NEAR_M);
      - `busy` are the manoeuvres (reflexes, avoidance, the motion guard) the NP3 starts, one window each
        from its start to its planned end (note "escape");
      - `ready` is when navigation starts (the NP3's INIT after POST, note "nav_start"); None: never, so
        nothing counts. A stimulus during POST counts from `ready`: the robot could not act before, but
        what it sensed then (switched on facing a wall) must be answered within the bound after it;
      - a stimulus is already being handled, and does not count, when it falls inside a `busy` window,
        or at or before the reaction that answered an earlier counted stimulus (one reaction answers
        everything sensed before it went out);
      - the reaction is the first MOVE the MMC receives at or after the start of the first manoeuvre
        starting at or after the stimulus (a task's MOVE that merely happens to follow is no reaction);
      - with no reaction before `end` (the run's end) the latency is `end` minus the stimulus if that
        exceeds 1 s (a stimulus never answered is a failure, not a gap), else the stimulus is not counted.
    """
    if ready is None:
        return []
    starts = sorted(a for a, _b in busy)
    out: list[dict[str, Any]] = []
    answered_until = -1.0
    for t, kind in sorted(stimuli):
        t = max(t, ready)
        if t <= answered_until or any(a <= t <= b for a, b in busy):
            continue
        begun = next((a for a in starts if a >= t), None)
        nxt = None if begun is None else next((m for m, _ in moves if m >= begun), None)
        if nxt is None:
            if end is None or end - t <= 1.0:
                continue
            nxt, answered = end, False
        else:
            answered = True
        out.append({"stimulus_s": round(t, 6), "kind": kind, "move_s": round(nxt, 6),
                    "latency_s": round(nxt - t, 6), "answered": answered})
        answered_until = nxt
    return out


def note_counts(notes: list[tuple[float, str, str, dict[str, Any]]],
                poses: list[tuple[float, float, float, float]] = ()) -> dict[str, dict[str, Any]]:
    """Per debug-port event: how often, first and last time (behaviours add events without touching sim2d),
    and how far the robot walked after its first occurrence (e.g. after a fault: did it stop?)."""
    out: dict[str, dict[str, Any]] = {}
    for t, _node, event, _data in notes:
        e = out.setdefault(event, {"count": 0, "first_s": round(t, 6), "last_s": round(t, 6)})
        e["count"] += 1
        e["last_s"] = round(t, 6)
    walked = [0.0]                         # path length up to each pose sample, computed once
    for a, b in zip(poses, poses[1:]):
        walked.append(walked[-1] + math.dist(a[1:3], b[1:3]))
    times = [p[0] for p in poses]
    for e in out.values():
        i = bisect_left(times, e["first_s"])
        e["walked_after_m"] = round(walked[-1] - walked[i], 4) if i < len(times) else 0.0
    return dict(sorted(out.items()))


def node_metrics(nodes: dict[str, Any]) -> dict[str, Any]:
    """What each node reports about itself on its debug port at the end (`debug_metrics()`, optional)."""
    out = {}
    for short, node in nodes.items():
        fn = getattr(node, "debug_metrics", None)
        if fn is not None and getattr(node.hw, "alive", True):
            out[short] = fn()
    return out


def battery_metrics(robot: "Robot", nodes: dict[str, Any]) -> dict[str, Any]:
    """seed 3.2.17 at a glance (issue 18): the battery's terminal voltage over the run (min/mean/final, every
    physics step), its open-circuit voltage at the end (the charge left), the current and how much of it was
    servos stalled (servo-seconds, the longest run of one servo), and what the PSC made of it: the mean it
    reports, its lowest, the lowest level it judged against the limit, its alarms."""
    log = robot.battery_log
    psc, mcp = nodes.get("PSC") or {}, nodes.get("MCP") or {}    # node_metrics: absent or dead nodes are missing
    return {
        "v_min": round(log.v_min, 3) if log.steps else None,
        "v_mean": round(log.v_sum / log.steps, 3) if log.steps else None,
        "v_final": round(robot.battery_voltage(), 3),
        "emf_final_v": round(robot.battery_emf(), 3),
        "charge_used_ah": round(robot.charge_used_ah, 4),
        "i_mean_a": round(log.i_sum / log.steps, 2) if log.steps else None,
        "i_max_a": round(log.i_max, 2),
        "stall_servo_s": round(log.stall_steps * robot.p.dt, 2),     # servo-seconds at stall current
        "stall_longest_s": round(log.stall_run_max * robot.p.dt, 2),  # the longest one servo stalled in a row
        "psc_mean_v": psc.get("mean_v"),
        "psc_mean_min_v": psc.get("mean_min_v"),
        "psc_level_min_v": psc.get("level_min_v"),
        "psc_alarms": psc.get("alarms"),
        "battery_low": mcp.get("battery_low"),
    }


def lookup(metrics: dict[str, Any], path: str) -> Any:
    """A metric by dotted path ('notes.escape.count'); None when absent, except the count of a debug-port note
    never written: 0 (a scenario can expect that something never happened, e.g. no close-up stimulus)."""
    parts = path.split(".")
    if len(parts) == 3 and parts[0] == "notes" and parts[2] == "count" and isinstance(metrics.get("notes"), dict):
        return metrics["notes"].get(parts[1], {}).get("count", 0)
    cur: Any = metrics
    for part in parts:
        if not isinstance(cur, dict) or part not in cur:
            return None
        cur = cur[part]
    return cur


def _obj(props: dict[str, Any], **extra: Any) -> dict[str, Any]:
    return {"type": "object", "properties": props, "additionalProperties": False, **extra}


def _leaves(*names: str) -> dict[str, Any]:
    return _obj({n: _VALUE for n in names})


_VALUE: dict[str, Any] = {"type": ["number", "boolean", "null", "array"]}   # a leaf metric (text ones say so)
_TEXT: dict[str, Any] = {"type": ["string", "null"]}
_JSON_TYPE = {bool: "boolean", int: "integer", float: "number", str: "string", type(None): "null"}


def schema_of(tp: Any) -> dict[str, Any]:
    """JSON Schema of a type annotation: a TypedDict (its keys, no others), list[X], dict[str, X], a union of
    scalars, bool, int, float, str, None. A node's debug_metrics() declares its record this way, next to the
    behaviour; anything else is a TypeError here, so an undeclarable shape is found at once."""
    if tp in _JSON_TYPE:
        return {"type": _JSON_TYPE[tp]}
    if is_typeddict(tp):
        return _obj({k: schema_of(v) for k, v in get_type_hints(tp).items()})
    origin, args = get_origin(tp), get_args(tp)
    if origin is list and len(args) == 1:
        return {"type": "array", "items": schema_of(args[0])}
    if origin is dict and len(args) == 2 and args[0] is str:
        return {"type": "object", "additionalProperties": schema_of(args[1])}
    if origin in (Union, types.UnionType) and all(a in _JSON_TYPE for a in args):
        return {"type": [_JSON_TYPE[a] for a in args]}
    raise TypeError(f"{tp!r}: not a metric type (TypedDict, list[X], dict[str, X], bool, int, float, str, None)")


@functools.cache
def node_schema(role: str) -> dict[str, Any]:
    """The declared shape of metrics.json `nodes.<NODE>` for a node of `role`: the return type of its behaviour's
    debug_metrics(), or no keys when it has none (or the role has no behaviour)."""
    fn = getattr(ROLES.get(role), "debug_metrics", None)
    return schema_of(get_type_hints(fn)["return"]) if fn is not None else _obj({})


def metrics_schema(spec: Any, measured: Sequence[str] = ()) -> dict[str, Any]:
    """The shape of metrics.json that build_metrics produces for this spec and `measure:` keys (JSON Schema).

    Declared here, next to build_metrics, so that a scenario's `expect.metrics` paths are checked at load
    time without a run (sim2d.scenario), and a test checks real runs against it (the two cannot drift).
    """
    bus = _leaves("load", "frames", "bytes", "collisions", "lost", "corrupted", "delayed")
    layer = _leaves("buses", "frames", "lost", "corrupted", "load_mean", "load_max")
    return _obj({
        "scenario": _TEXT, "trace_hash": _TEXT,
        **{k: _VALUE for k in ("seed", "duration_s", "distance_walked_m", "displacement_m", "final_pose",
                               "collisions", "min_clearance_m", "blocked_leg_events", "pit_events", "fell",
                               "tilt_events", "max_tilt_deg", "reach_time_s", "entered_forbidden_s", "moves",
                               "reaction_latencies_s", "max_reaction_s", "frames", "frame_loss", "frames_corrupted")},
        "battery": _leaves("v_min", "v_mean", "v_final", "emf_final_v", "i_mean_a", "i_max_a", "stall_servo_s",
                           "stall_longest_s", "charge_used_ah", "psc_mean_v", "psc_mean_min_v", "psc_level_min_v", "psc_alarms", "battery_low"),
        "post": _obj({"verdict": {"enum": [*spec.post.verdicts, None]}, "missing": _VALUE, "reasons": _VALUE,
                      "time_s": _VALUE}),
        "buses": _obj({name: bus for name in spec.buses}),
        "bus_layers": _obj({str(level): layer for level in sorted({b.level for b in spec.buses.values()})}),
        "notes": {"type": "object", "additionalProperties": _leaves("count", "first_s", "last_s", "walked_after_m")},
        "sound": _leaves("events", "final_heading_error_deg"),
        "rcp": _leaves("keys_typed", "screen_bytes"),
        "nodes": _obj({n.short: node_schema(n.role) for n in spec.nodes}),
        "motion": motion_schema(),
        **nav_schema(measured),
        # tracecheck.validate.Report.metrics: the run's trace held to the verified protocol (issue 11)
        "protocol": _obj({**{k: _VALUE for k in ("violations", "first", "requests", "served", "declined",
                                                 "unchecked", "starved")},
                          "by_rule": {"type": "object", "additionalProperties": _VALUE},
                          **{k: _obj({b: _VALUE for b in spec.buses}) for k in ("max_wait_slots", "k_slots")},
                          "checked": {"type": "object", "additionalProperties": _VALUE},
                          "skipped": {"type": "object", "additionalProperties": _TEXT}}),   # rule -> why not
        "reactions": {"type": "array"},         # one record per reaction (the report's sequence charts)
        "expectations": {"type": "array"},      # added by the runner to metrics.json
    })


def metric_path_problem(schema: dict[str, Any], path: str) -> str | None:
    """Why `path` ('notes.escape.count') can never name a metric of `schema`, or None when it can."""
    found = metric_node(schema, path)
    return found if isinstance(found, str) else None


def metric_node(schema: dict[str, Any], path: str) -> dict[str, Any] | str:
    """The schema of the metric at `path`, or why there is none."""
    node = schema
    done: list[str] = []
    for part in path.split("."):
        if node.get("type") != "object":
            return f"{'.'.join(done)} is a single value, it has no {part!r}"
        props = node.get("properties", {})
        nxt = props.get(part, node.get("additionalProperties", False))
        if nxt is False:
            where = ".".join(done) or "the metrics"
            known = ", ".join(props) if len(props) <= 12 else ", ".join(list(props)[:12]) + ", ..."
            return f"{where} has no {part!r} (one of {known})"
        node = nxt
        done.append(part)
    return node


def trace_hash(frames: list[TraceEntry], poses: list[tuple[float, float, float, float]]) -> str:
    """SHA-256 over every frame (times, bus, sender, bytes sent and heard, flags) and the pose log."""
    h = hashlib.sha256()
    for f in frames:
        h.update(f"{f.start:.9f} {f.end:.9f} {f.bus} {f.sender} {f.sent.hex()} "
                 f"{f.heard.hex() if f.heard is not None else '-'} {','.join(f.flags)}\n".encode())
    for t, x, y, th in poses:
        h.update(f"{t:.3f} {x:.9f} {y:.9f} {th:.9f}\n".encode())
    return h.hexdigest()


def build_metrics(sim: "Simulation") -> dict[str, Any]:
    from sim2d.level0_io import rcp_metrics, sound_metrics
    from sim2d.nav_metrics import nav_metrics
    from sim2d.gait_metrics import motion_metrics
    dur = sim.scenario.duration
    buses = {}
    for name, b in sim.buses.items():
        st = b.stats
        buses[name] = {"load": round(st.busy_s / dur, 4), "frames": st.frames, "bytes": st.bytes,
                       "collisions": st.collisions, "lost": st.lost, "corrupted": st.corrupted, "delayed": st.delayed}
    layers: dict[str, dict[str, Any]] = {}
    for name, b in buses.items():      # seed 3.2.1: level 0 first-level bus, 1 leg/sensor buses, 2 joint buses
        layer = layers.setdefault(str(sim.spec.buses[name].level), {"buses": [], "frames": 0, "lost": 0, "corrupted": 0})
        layer["buses"].append(name)
        for k in ("frames", "lost", "corrupted"):
            layer[k] += b[k]
    for layer in layers.values():
        loads = [buses[n]["load"] for n in layer["buses"]]
        layer["load_mean"], layer["load_max"] = round(sum(loads) / len(loads), 4), max(loads)
    v = sim.verdict
    ready = next((t for t, _node, event, _d in sim.notes if event == "nav_start"), None)
    reacted = reactions(sim.stimuli, sim.moves, sim.escapes, ready, dur)
    lat = [r["latency_s"] for r in reacted]
    ev = sim.robot.events
    x0, y0, _ = sim.scenario.start
    x, y, th = sim.robot.pose
    nodes = node_metrics(sim.nodes)
    return {
        "scenario": sim.scenario.name,
        "seed": sim.scenario.seed,
        "duration_s": dur,
        "post": {"verdict": v.verdict if v else None, "missing": list(v.missing) if v else [],
                 "reasons": list(v.reasons) if v else [], "time_s": sim.verdict_time},
        "distance_walked_m": round(sim.distance, 4),
        "displacement_m": round(math.hypot(x - x0, y - y0), 4),
        "final_pose": [round(x, 4), round(y, 4), round(math.degrees(th), 2)],
        "collisions": ev.collisions,
        "min_clearance_m": None if math.isinf(sim.min_clearance) else round(sim.min_clearance, 4),
        "blocked_leg_events": sum(1 for e in sim.events if e[1] == "blocked"),
        "pit_events": sum(1 for e in sim.events if e[1] == "pit") + (1 if ev.fell else 0),
        "fell": ev.fell,
        "tilt_events": sim.tilt_events,
        "max_tilt_deg": round(sim.max_tilt, 2),
        "reach_time_s": sim.reach_time,
        "entered_forbidden_s": sim.entered_time,
        "moves": len(sim.moves),
        "reactions": reacted,                    # stimulus, kind, MOVE time (the report's sequence charts)
        "reaction_latencies_s": lat,
        "max_reaction_s": max(lat) if lat else None,
        "buses": buses,
        "bus_layers": dict(sorted(layers.items())),
        "frames": len(sim.frames),
        "frame_loss": sum(b["lost"] for b in buses.values()),
        "frames_corrupted": sum(b["corrupted"] for b in buses.values()),
        "battery": battery_metrics(sim.robot, nodes),
        "notes": note_counts(sim.notes, sim.poses),
        "sound": sound_metrics(sim),             # sim2d.level0_io: sound events, final heading error
        "rcp": rcp_metrics(sim),                 # keys typed on the RCP console
        "nodes": nodes,
        "motion": motion_metrics(sim),           # sim2d.gait_metrics: body-frame motion per (gait, MOVE)
        **nav_metrics(sim),                      # sim2d.nav_metrics: coverage, wall_band (scenario `measure:`)
        "trace_hash": trace_hash(sim.frames, sim.poses),
        "protocol": protocol_metrics(sim),
    }


def protocol_metrics(sim: "Simulation") -> dict[str, Any]:
    """The run's bus trace held to the verified protocol (tracecheck): violations (0 expected), waits, K."""
    lines = ["\t".join(COLUMNS)] + sim.trace_rows()
    trace = parse_lines(lines, f"{sim.scenario.name}/trace.tsv", set(sim.spec.buses))
    return validate(trace, sim.spec, dict(sim.scenario.arbitration)).metrics()


def check_expectations(scenario: Any, m: dict[str, Any]) -> list[tuple[str, bool, str]]:
    """(name, passed, detail) for each expectation the scenario declares."""
    e = scenario.expect
    out: list[tuple[str, bool, str]] = []
    if e.post is not None:
        got = m["post"]["verdict"]
        out.append(("post", got == e.post, f"expected POST {e.post}, got {got} {m['post']['reasons']}"))
    if e.no_collision:
        out.append(("no_collision", m["collisions"] == 0, f"{m['collisions']} collision(s)"))
    if e.reach is not None:
        t = m["reach_time_s"]
        ok = t is not None and t <= e.reach[1]
        out.append(("reach", ok, f"region reached at {t} s, limit {e.reach[1]} s" if t is not None else
                    f"region not reached within {e.reach[1]} s (final pose {m['final_pose']})"))
    if e.min_clearance is not None:
        c = m["min_clearance_m"]
        out.append(("min_clearance", c is not None and c >= e.min_clearance, f"min clearance {c} m, needed {e.min_clearance} m"))
    if e.never_moves:
        out.append(("never_moves", m["distance_walked_m"] < 0.005, f"walked {m['distance_walked_m']} m"))
    if e.min_distance is not None:
        out.append(("min_distance", m["distance_walked_m"] >= e.min_distance,
                    f"walked {m['distance_walked_m']} m, needed {e.min_distance} m"))
    if e.max_reaction is not None:
        r = m["max_reaction_s"]
        out.append(("max_reaction", r is None or r <= e.max_reaction,   # no stimulus to answer: nothing was slow
                    f"slowest reaction {r} s, limit {e.max_reaction} s" if r is not None else "no stimulus to answer"))
    if e.stay_out is not None:
        t = m["entered_forbidden_s"]
        out.append(("stay_out", t is None, "never entered the region" if t is None else f"entered the region at {t} s"))
    if e.order is not None:
        first, then = (lookup(m, f"notes.{n}.first_s") for n in (e.order.first, e.order.then))
        ok = first is not None and (then is None or first < then)
        out.append(("order", ok, f"first {e.order.first} at {first} s, first {e.order.then} at {then} s"))
    if "protocol.violations" not in (e.metrics or {}) and "protocol" in m:
        # issue 11: every run is a behaviour the verified protocol allows
        p = m["protocol"]
        out.append(("protocol.violations eq", p["violations"] == 0,
                    f"protocol.violations = {p['violations']}, eq 0" + (f"; first: {p['first']}" if p["first"] else "")))
    for path, bounds in (e.metrics or {}).items():
        v = lookup(m, path)
        for op, limit in bounds.items():
            if op == "min":
                ok = isinstance(v, (int, float)) and v >= limit
            elif op == "max":
                ok = isinstance(v, (int, float)) and v <= limit
            else:
                ok = v == limit
            out.append((f"{path} {op}", ok, f"{path} = {v}, {op} {limit}"))
    return out
