"""Scenario files: YAML in, a checked, immutable Scenario out.

Errors are one line, `file:line: message`. A scenario may `include:` shared
definitions: included files come first, list-valued world keys (walls,
obstacles, ...) are concatenated, mapping keys (arena, robot, expect) merge
key by key, and the including file wins on conflicts.

Files are read with the toolkit's one hardened YAML loader (arachnae.yamlio),
the structure is checked with JSON Schema (sim2d/scenario.schema.yaml) as the
spec's is, and the meaning here, before any run starts: a plain `name`, simple
polygons and every position inside the arena, a start pose on free ground,
events before the end of the run, metric paths a run produces, min <= max.
"""
from __future__ import annotations

import copy
import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any


from arachnae.errors import UserError, located
from arachnae.validation import Validator, check_schema, field_name, fill_defaults
from arachnae.yamlio import LDict, LList, load_yaml, locate, new_dict, new_list
from behaviours.rcp_keys import KEYMAP
from sim2d.geometry import (WALL_RADIUS, on_one_line, point_in_polygon, polygons_overlap, seg_seg_distance,
                            self_crossing, signed_area, to_world)
from sim2d.metrics import metric_node, metrics_schema
from sim2d.robot_params import DEFAULT as DEFAULT_PARAMS

LIST_KEYS = ("walls", "obstacles", "pits", "slopes", "lights", "heat", "sounds", "faults", "operator")
MAP_KEYS = ("arena", "robot", "expect", "measure", "speech", "arbitration")
FAULT_KINDS = ("kill", "mute", "bus", "sensor", "request", "collide")   # scenario.schema.yaml faults
_SCHEMA: dict[str, Any] = load_yaml(Path(__file__).with_name("scenario.schema.yaml"))


@dataclass(frozen=True)
class Obstacle:
    polygon: tuple[tuple[float, float], ...]
    height: float


@dataclass(frozen=True)
class Slope:
    polygon: tuple[tuple[float, float], ...]
    incline_x: float   # degrees, rising along +x
    incline_y: float   # degrees, rising along +y


@dataclass(frozen=True)
class Light:
    pos: tuple[float, float]
    intensity: float   # candela: lux = intensity / d^2


@dataclass(frozen=True)
class Heat:
    pos: tuple[float, float]
    temperature: float  # degrees C at the source
    radius: float       # metres to fall to 1/e of the excess


@dataclass(frozen=True)
class Sound:
    at: float
    pos: tuple[float, float]
    level_db: float


@dataclass(frozen=True)
class OperatorKeys:
    """Keys typed on the UIC/RCP's VT100 console at simulated time `at` (seed 4.1)."""

    at: float
    keys: str


def _rcp_keys_check(keys: str) -> str | None:
    bad = sorted({k for k in keys if k.upper() not in KEYMAP})
    if not keys:
        return "give at least one key"
    if bad:
        return f"{''.join(bad)!r} is not an RCP key (one of {''.join(sorted(KEYMAP)).strip()} or space)"
    return None


@dataclass(frozen=True)
class Fault:
    at: float
    until: float | None
    kind: str                 # one of FAULT_KINDS
    node: str | None = None
    bus: str | None = None
    loss: float = 0.0
    corrupt: float = 0.0
    delay: float = 0.0
    noise: float = 0.0        # sensor: extra spread (1 sigma) of every reading, in the sensor's unit
    nodes: tuple[str, ...] = ()   # collide: the stations deaf to each other for a slot


@dataclass(frozen=True)
class Contention:
    """Worst contention on demand (seed 5.2 latency): whenever a stimulus of kind `stimulus` is noted, every other
    requesting slave of `bus` asks for the line at that same instant."""

    bus: str
    stimulus: str


@dataclass(frozen=True)
class NoteOrder:
    """`expect.order`: the note `first` is written, and before any `then` note (or no `then` note at all).

    Why: a claim such as "the sonar avoids the wall before anything comes within whisker reach" (sonar_first) is
    about the order of events on the approach, not about a count over the whole run (a touch while walking along
    the wall afterwards does not contradict it)."""

    first: str
    then: str


@dataclass(frozen=True)
class Expectations:
    post: str | None = None
    no_collision: bool = False
    reach: tuple[tuple[tuple[float, float], ...], float] | None = None   # (region, within seconds)
    min_clearance: float | None = None
    never_moves: bool = False
    min_distance: float | None = None
    max_reaction: float | None = None   # seed 5.2: stimulus -> reaction within this many seconds
    stay_out: tuple[tuple[float, float], ...] | None = None           # the body centre never enters
    order: NoteOrder | None = None                                   # one debug-port note before another
    metrics: dict[str, dict[str, Any]] | None = None                  # dotted metric path -> {min, max, eq}


@dataclass(frozen=True)
class Scenario:
    path: str
    name: str
    duration: float
    seed: int
    size: tuple[float, float]
    boundary_walls: bool
    ambient_lux: float
    ambient_temp: float
    walls: tuple[tuple[tuple[float, float], ...], ...]
    obstacles: tuple[Obstacle, ...]
    pits: tuple[tuple[tuple[float, float], ...], ...]
    slopes: tuple[Slope, ...]
    lights: tuple[Light, ...]
    heat: tuple[Heat, ...]
    sounds: tuple[Sound, ...]
    start: tuple[float, float, float]   # x, y, heading in radians
    task: str
    absent: tuple[str, ...]
    faults: tuple[Fault, ...]
    expect: Expectations = field(default_factory=Expectations)
    measure: dict[str, Any] | None = None    # navigation metrics to compute (sim2d.nav_metrics): coverage, wall_band
    operator: tuple[OperatorKeys, ...] = ()   # keys typed on the RCP console (seed 4.1)
    speech_wav: bool = False                   # also write the SSC's utterances as WAV (espeak-ng)
    battery_charge: float = 1.0                # state of charge at power-on
    battery_ah: float | None = None            # battery capacity; None: the robot's (sim2d.robot_params)
    contention: Contention | None = None       # every slave of a bus requests as a stimulus fires
    arbitration: dict[str, str] = field(default_factory=dict)   # bus -> 'seed' | 'spec' (replays of the checker)

    def with_seed(self, seed: int) -> "Scenario":
        from dataclasses import replace
        return replace(self, seed=seed)


def _fault_problem(f: dict, bus_of: dict[str, str | None]) -> str | None:
    kinds = [k for k in FAULT_KINDS if f.get(k) is not None]
    if len(kinds) != 1:
        return f"a fault names exactly one of {', '.join(FAULT_KINDS)}"
    if kinds[0] == "request" and f.get("until") is not None:
        return "a request happens at one time: no until"
    if kinds[0] == "collide" and bus_of and len({bus_of.get(n) for n in f["collide"]}) != 1:
        return "collide: the nodes must share one bus"
    if (kinds[0] == "sensor") != (f["noise"] > 0):
        return "a sensor fault needs noise > 0" if kinds[0] == "sensor" else "noise belongs to a sensor fault"
    if kinds[0] == "bus" and not (f["loss"] or f["corrupt"] or f["delay"]):
        return "a bus fault needs loss, corrupt or delay"
    if kinds[0] != "bus" and (f["loss"] or f["corrupt"] or f["delay"]):
        return "loss, corrupt and delay belong to a bus fault"
    if f.get("until") is not None and f["until"] <= f["at"]:
        return "until must be after at"
    return None


def scenario_schema(spec: Any) -> dict[str, Any]:
    """sim2d/scenario.schema.yaml, with the spec's node and bus names when a spec is given."""
    schema = copy.deepcopy(_SCHEMA)
    if spec is not None:
        schema["$defs"]["node"] = {"enum": [n.short for n in spec.nodes]}
        schema["$defs"]["bus"] = {"enum": sorted(spec.buses)}
        contended = sorted(b for b, x in spec.buses.items() if x.request_message)
        schema["$defs"]["requester"] = {"enum": [n.short for b in contended for n in spec.requesters(b)]}
        arb = schema["properties"]["arbitration"]
        arb["properties"] = {b: arb["additionalProperties"] for b in contended}
        arb["additionalProperties"] = False
    return schema


# -- loading and includes -------------------------------------------------------------
def _read(path: Path, shown: str) -> LDict:
    if not path.is_file():
        raise UserError(located(shown, None, "no such scenario file"))
    doc = load_yaml(path, shown)
    if doc is None:
        raise UserError(located(shown, None, "scenario is empty"))
    if not isinstance(doc, LDict):
        raise locate(doc, [], "a scenario is a mapping of keys") if isinstance(doc, LList) \
            else UserError(located(shown, 1, "a scenario is a mapping of keys"))
    return doc


def gather_includes(path: Path, shown: str, stack: tuple[Path, ...], merged: LDict) -> None:
    """Merge one file into `merged`: its includes first, then its own keys (lists concatenate,
    mappings merge key by key, anything else: the later file wins). Every entry keeps its file and line."""
    doc = _read(path, shown)
    includes = doc.get("include", [])
    for i, inc in enumerate(includes if isinstance(includes, list) else [includes]):
        where_ = ["include", i] if isinstance(includes, list) else ["include"]
        if not isinstance(inc, str) or not inc:
            raise locate(doc, where_, "include: expected a file name")
        target = (path.parent / inc).resolve()
        if target in stack:
            raise locate(doc, where_, f"include cycle through {inc}")
        if not target.is_file():
            raise locate(doc, where_, f"included file {inc!r} not found")
        gather_includes(target, str(Path(shown).parent / inc), stack + (target,), merged)
    for key, value in doc.items():
        if key == "include":
            continue
        line = doc.key_lines[key]
        if key in LIST_KEYS and key in merged:
            if not isinstance(value, LList) or not isinstance(merged[key], LList):
                bad = doc if not isinstance(value, LList) else merged
                raise locate(bad, [key], f"{key}: expected a list")
            for j, item in enumerate(value):
                merged[key].add(item, value.item_lines[j], value.item_paths[j])
        elif key in MAP_KEYS and key in merged:
            if not isinstance(value, LDict) or not isinstance(merged[key], LDict):
                bad = doc if not isinstance(value, LDict) else merged
                raise locate(bad, [key], f"{key}: expected a mapping")
            for k, v in value.items():
                merged[key].put(k, v, value.key_lines[k], value.key_paths[k])
        else:
            if key in LIST_KEYS and isinstance(value, LList):
                value = _copy_list(value)        # later files add to it: keep this file's list as it is
            elif key in MAP_KEYS and isinstance(value, LDict):
                value = _copy_dict(value)
            merged.put(key, value, line, shown)
            merged.key_lines[key], merged.line = line, doc.line


def _copy_list(items: LList) -> LList:
    out = new_list(items.path, items.line)
    for j, item in enumerate(items):
        out.add(item, items.item_lines[j], items.item_paths[j])
    return out


def _copy_dict(d: LDict) -> LDict:
    out = new_dict(d.path, d.line)
    for k, v in d.items():
        out.put(k, v, d.key_lines[k], d.key_paths[k])
    return out


def load_scenario(path: str | Path, spec: Any = None) -> Scenario:
    """Read and check a scenario: structure (sim2d/scenario.schema.yaml), then meaning (_check_meaning).

    `spec` (codegen.model) adds node and bus names and the metric paths that depend on them."""
    shown = str(path)
    p = Path(path).resolve()
    doc = new_dict(shown, 1)
    gather_includes(p, shown, (p,), doc)
    schema = scenario_schema(spec)
    check_schema(doc, schema)
    fill_defaults(doc, schema)
    _check_meaning(doc, spec)
    return _build(doc, shown)


# -- meaning ------------------------------------------------------------------------------
NAME_RE = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.+-]{0,99}")   # a folder name: never a path, '.', '..' or '-x'
PARAMS = DEFAULT_PARAMS


def safe_name(text: str) -> str:
    """A file stem as a run name: characters outside NAME_RE become '_' (the default `name`)."""
    name = re.sub(r"[^A-Za-z0-9_.+-]", "_", text)[:100]
    return name if NAME_RE.fullmatch(name) else ("run" + name)[:100]


def _polygons(doc: LDict) -> list[tuple[list[Any], Any]]:
    """(path, corners) of every polygon in the scenario."""
    out: list[tuple[list[Any], Any]] = []
    for key in ("obstacles", "pits", "slopes"):
        out += [([key, i, "polygon"], item["polygon"]) for i, item in enumerate(doc.get(key, []))]
    measure, expect = doc.get("measure", {}), doc.get("expect", {})
    if "coverage" in measure:
        out.append((["measure", "coverage", "region"], measure["coverage"]["region"]))
    if "reach" in expect:
        out.append((["expect", "reach", "region"], expect["reach"]["region"]))
    if "stay_out" in expect:
        out.append((["expect", "stay_out"], expect["stay_out"]))
    return out


def _points(doc: LDict) -> list[tuple[list[Any], tuple[float, float]]]:
    """(path, point) of every position that must lie in the arena."""
    out = [([*path, j], tuple(pt)) for path, poly in _polygons(doc) for j, pt in enumerate(poly)]
    out += [(["walls", i, j], tuple(pt)) for i, wall in enumerate(doc.get("walls", [])) for j, pt in enumerate(wall)]
    for key in ("lights", "heat", "sounds"):
        out += [([key, i, "pos"], tuple(item["pos"])) for i, item in enumerate(doc.get(key, []))]
    return out


def _check_meaning(doc: LDict, spec: Any) -> None:
    """What the schema cannot say: names, geometry, the start pose, times, faults, keys, metric paths."""
    name = doc.get("name")
    if name is not None and not NAME_RE.fullmatch(name):
        raise locate(doc, ["name"], f"name: {name!r} is not a plain folder name (letters, digits, _ . + -; "
                                    f"it names the output folder)")
    w, h = doc["arena"]["size"]
    for path, poly in _polygons(doc):
        what = field_name(path)
        corners = [tuple(pt) for pt in poly]
        crossing = None if on_one_line(corners) else self_crossing(corners)
        if crossing is not None:
            raise locate(doc, path, f"{what}: polygon crosses itself (edges {crossing[0]} and {crossing[1]}); "
                                    "list its corners in order around it")
        if abs(signed_area(corners)) < 1e-9:
            raise locate(doc, path, f"{what}: polygon has no area")
    for i, wall in enumerate(doc.get("walls", [])):
        for j in range(len(wall) - 1):
            if tuple(wall[j]) == tuple(wall[j + 1]):       # a typo: a wall of no length blocks nothing
                raise locate(doc, ["walls", i, j + 1], f"walls[{i}][{j + 1}]: point repeats the one before; "
                                                       "a wall segment needs a length")
    for path, (x, y) in _points(doc):
        if not (0 <= x <= w and 0 <= y <= h):
            raise locate(doc, path, f"{field_name(path)}: point ({x}, {y}) lies outside the arena {w} x {h} m")
    duration = doc["duration"]
    for key in ("faults", "operator", "sounds"):
        for i, item in enumerate(doc.get(key, [])):
            if item["at"] >= duration:
                raise locate(doc, [key, i, "at"], f"{key}[{i}].at: {item['at']} s is not before the end of the run "
                                                  f"({duration} s)")
    bus_of = {n.short: n.bus for n in spec.nodes} if spec is not None else {}
    for i, f in enumerate(doc.get("faults", [])):
        problem = _fault_problem(f, bus_of)
        if problem:
            raise locate(doc, ["faults", i], f"faults[{i}]: {problem}")
    for i, o in enumerate(doc.get("operator", [])):
        problem = _rcp_keys_check(o["keys"])
        if problem:
            raise locate(doc, ["operator", i, "keys"], f"operator[{i}].keys: {problem}")
    band = doc.get("measure", {}).get("wall_band")
    if band is not None and not band["max"] > band["min"]:
        raise locate(doc, ["measure", "wall_band"], "measure.wall_band: max must be above min")
    _check_start(doc)
    _check_metric_paths(doc, spec)


def _check_start(doc: LDict) -> None:
    """seed 1.2: the robot starts standing on free ground: body and feet inside the arena, the body clear of
    walls and of obstacles taller than its underside, no foot over a pit or inside an obstacle it could not
    step onto (sim2d.robot_params: the same body and leg geometry the simulation uses)."""
    x, y, heading = doc["robot"]["pose"]
    w, h = doc["arena"]["size"]
    pose = (x, y, math.radians(heading))

    def fail(problem: str) -> UserError:
        return locate(doc, ["robot", "pose"], f"robot.pose: {problem}")

    if not (0 <= x <= w and 0 <= y <= h):
        raise fail(f"start pose ({x}, {y}) lies outside the arena {w} x {h} m")
    half_l, half_w = PARAMS.body_length / 2, PARAMS.body_width / 2
    body = [to_world(pose, bx, by) for bx, by in ((half_l, half_w), (-half_l, half_w), (-half_l, -half_w),
                                                   (half_l, -half_w))]
    feet = {leg: to_world(pose, *PARAMS.neutral_foot(leg)) for leg in PARAMS.legs}
    for label, (px, py) in [("the body", c) for c in body] + [(f"leg {leg}'s foot", f) for leg, f in feet.items()]:
        if not (0 <= px <= w and 0 <= py <= h):
            raise fail(f"{label} at ({px:.3f}, {py:.3f}) lies outside the arena {w} x {h} m")
    walls = [list(map(tuple, wall)) for wall in doc.get("walls", [])]
    if doc["arena"]["boundary_walls"]:
        walls.append([(0.0, 0.0), (w, 0.0), (w, h), (0.0, h), (0.0, 0.0)])
    for i, wall in enumerate(walls):
        for a, b in zip(wall, wall[1:]):
            if any(seg_seg_distance(body[k - 1], body[k], a, b) <= WALL_RADIUS for k in range(4)):
                which = f"walls[{i}]" if i < len(doc.get("walls", [])) else "the arena's boundary wall"
                raise fail(f"the body at ({x}, {y}) touches {which}")
    for i, ob in enumerate(doc.get("obstacles", [])):
        poly = [tuple(pt) for pt in ob["polygon"]]
        if ob["height"] > PARAMS.body_clearance and polygons_overlap(body, poly):
            raise fail(f"the body at ({x}, {y}) overlaps obstacles[{i}] ({ob['height']} m high)")
        for leg, (fx, fy) in feet.items():
            if ob["height"] > PARAMS.step_limit and point_in_polygon(fx, fy, poly):
                raise fail(f"leg {leg}'s foot starts inside obstacles[{i}] ({ob['height']} m high)")
    for i, pit in enumerate(doc.get("pits", [])):
        poly = [tuple(pt) for pt in pit["polygon"]]
        for leg, (fx, fy) in feet.items():
            if point_in_polygon(fx, fy, poly):
                raise fail(f"leg {leg}'s foot starts over pits[{i}]")
        if point_in_polygon(x, y, poly):
            raise fail(f"the body starts over pits[{i}]")


def _check_metric_paths(doc: LDict, spec: Any) -> None:
    """`expect.metrics` names metrics a run produces (sim2d.metrics.metrics_schema) and bounds that can hold."""
    bounds = doc.get("expect", {}).get("metrics", {})
    if not bounds:
        return
    schema = metrics_schema(spec, list(doc.get("measure", {}))) if spec is not None else None
    absent = set(doc["robot"]["absent"])
    for path, b in bounds.items():
        where_ = ["expect", "metrics", path]
        parts = path.split(".")
        if not all(parts):
            raise locate(doc, where_, f"expect.metrics: {path!r} is not a dotted metric path")
        if schema is not None:
            node = metric_node(schema, path)
            if isinstance(node, str):
                raise locate(doc, where_, f"expect.metrics: {path!r} names no metric: {node}")
            _check_operands(doc, where_, path, b, node)
        if parts[0] == "nodes" and len(parts) > 1 and parts[1] in absent:
            raise locate(doc, where_, f"expect.metrics: {path!r}: node {parts[1]} is absent in this scenario")
        if "min" in b and "max" in b and b["min"] > b["max"]:
            raise locate(doc, where_, f"expect.metrics.{path}: min {b['min']} is above max {b['max']}")
        if "eq" in b and len(b) > 1:
            raise locate(doc, where_, f"expect.metrics.{path}: eq with min or max; give one or the other")


def _check_operands(doc: LDict, where_: list[Any], path: str, bounds: Any, metric: dict[str, Any]) -> None:
    """An `eq` the metric can never equal (text for a number, a verdict the spec lacks) or a min/max on a
    metric that is not a number is a mistake found now, not a run that fails at its end."""
    valid = Validator(metric).is_valid
    if "eq" in bounds and not valid(bounds["eq"]):
        raise locate(doc, where_ + ["eq"], f"expect.metrics.{path}: eq {bounds['eq']!r} is not a value this metric takes")
    if metric.get("type") == "integer":     # a count: any number bounds it (min 0.5 means at least 1)
        valid = Validator({"type": "number"}).is_valid
    for key in ("min", "max"):
        if key in bounds and not valid(bounds[key]):
            raise locate(doc, where_ + [key], f"expect.metrics.{path}: {key} {bounds[key]!r}: this metric is not a number")


def _pt(p: Any) -> tuple[float, float]:
    return (float(p[0]), float(p[1]))


def _poly(p: Any) -> tuple[tuple[float, float], ...]:
    return tuple(_pt(q) for q in p)


def _plain(value: Any) -> Any:
    """LDict/LList -> dict/list with float numbers (what the simulation's metrics code reads)."""
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_plain(v) for v in value]
    return float(value) if isinstance(value, (int, float)) and not isinstance(value, bool) else value


def _build(v: dict[str, Any], shown: str) -> Scenario:
    """The checked document (defaults filled in) as an immutable Scenario."""
    arena, robot = v["arena"], v["robot"]
    exp = v.get("expect", {})
    measure = _plain(v.get("measure")) or None
    if measure:
        for m in measure.values():
            if "region" in m:
                m["region"] = _poly(m["region"])
    faults = tuple(
        Fault(at=float(f["at"]), until=None if f.get("until") is None else float(f["until"]),
              kind=next(k for k in FAULT_KINDS if f.get(k) is not None),
              node=f.get("kill") or f.get("mute") or f.get("sensor") or f.get("request") or (f.get("collide") or [None])[0],
              bus=f.get("bus"), loss=float(f["loss"]), corrupt=float(f["corrupt"]), delay=float(f["delay"]),
              noise=float(f["noise"]), nodes=tuple(f.get("collide") or ()))
        for f in v.get("faults", [])
    )
    x, y, heading = (float(c) for c in robot["pose"])
    metrics = {k: {op: b if isinstance(b, (str, bool)) else float(b) for op, b in bounds.items()}
               for k, bounds in exp.get("metrics", {}).items()}
    return Scenario(
        path=shown,
        name=v.get("name") or safe_name(Path(shown).stem),
        duration=float(v["duration"]),
        seed=v["seed"],
        size=_pt(arena["size"]),
        boundary_walls=arena["boundary_walls"],
        ambient_lux=float(arena["ambient_lux"]),
        ambient_temp=float(arena["ambient_temp"]),
        walls=tuple(_poly(w) for w in v.get("walls", [])),
        obstacles=tuple(Obstacle(_poly(o["polygon"]), float(o["height"])) for o in v.get("obstacles", [])),
        pits=tuple(_poly(p["polygon"]) for p in v.get("pits", [])),
        slopes=tuple(Slope(_poly(s["polygon"]), float(s["incline_x"]), float(s["incline_y"]))
                     for s in v.get("slopes", [])),
        lights=tuple(Light(_pt(li["pos"]), float(li["intensity"])) for li in v.get("lights", [])),
        heat=tuple(Heat(_pt(h["pos"]), float(h["temperature"]), float(h["radius"])) for h in v.get("heat", [])),
        sounds=tuple(Sound(float(s["at"]), _pt(s["pos"]), float(s["level_db"])) for s in v.get("sounds", [])),
        start=(x, y, math.radians(heading)),
        task=robot["task"],
        absent=tuple(robot["absent"]),
        faults=faults,
        measure=measure,
        expect=Expectations(
            post=exp.get("post"), no_collision=exp.get("no_collision", False),
            reach=(_poly(exp["reach"]["region"]), float(exp["reach"]["within"])) if "reach" in exp else None,
            min_clearance=_opt(exp.get("min_clearance")), never_moves=exp.get("never_moves", False),
            min_distance=_opt(exp.get("min_distance")), max_reaction=_opt(exp.get("max_reaction")),
            stay_out=_poly(exp["stay_out"]) if "stay_out" in exp else None,
            order=NoteOrder(exp["order"]["first"], exp["order"]["then"]) if "order" in exp else None,
            metrics=metrics or None,
        ),
        operator=tuple(sorted((OperatorKeys(float(o["at"]), o["keys"]) for o in v.get("operator", [])),
                              key=lambda o: o.at)),
        speech_wav=v.get("speech", {}).get("wav", False),
        battery_charge=float(robot["battery_charge"]),
        battery_ah=_opt(robot.get("battery_ah")),
        contention=Contention(v["contention"]["bus"], v["contention"]["stimulus"]) if v.get("contention") else None,
        arbitration=dict(v.get("arbitration", {})),
    )


def _opt(value: Any) -> float | None:
    return None if value is None else float(value)
