"""Issue 10, item 5: scenarios are checked for meaning at load time, before any run starts."""
from __future__ import annotations

from typing import TypedDict

import pytest

from arachnae.errors import UserError
from sim2d.geometry import is_convex
from sim2d.scenario import load_scenario
from tests.hostile.conftest import assert_one_line_error, snapshot

ROOM = "duration: 20\narena: {size: [4, 3]}\nrobot: {pose: [1, 1.5, 0]}\n"     # lines 1-3; extras start at 4

# (name, extra YAML after ROOM or a replacement of the robot line, line of the error, fragment)
CASES = [
    ("start outside the arena", "robot: {pose: [5, 1, 0]}", 3, "start pose (5, 1) lies outside the arena"),
    ("body over the arena edge", "robot: {pose: [0.1, 1.5, 0]}", 3, "outside the arena"),
    ("body on a wall", "walls: [[[1, 0.5], [1, 2.5]]]\n", 3, "touches walls[0]"),
    ("body in a high obstacle", "obstacles: [{polygon: [[0.9, 1.4], [1.1, 1.4], [1.1, 1.6]], height: 0.5}]\n", 3,
     "overlaps obstacles[0]"),
    ("foot in a tall obstacle", "obstacles: [{polygon: [[0.8, 1.65], [1.3, 1.65], [1.3, 1.9], [0.8, 1.9]], height: 0.065}]\n",
     3, "foot starts inside obstacles[0]"),
    ("foot over a pit", "pits: [{polygon: [[0.8, 1.6], [1.3, 1.6], [1.3, 2.0], [0.8, 2.0]]}]\n", 3, "foot starts over pits[0]"),
    ("bow-tie obstacle", "obstacles: [{polygon: [[2, 0.5], [3, 1.5], [3, 0.5], [2, 1.5]], height: 0.2}]\n", 4,
     "polygon crosses itself"),
    ("bow-tie pit", "pits:\n  - polygon: [[2, 0.5], [3, 1.5], [3, 0.5], [2, 1.5]]\n", 5, "crosses itself"),
    ("repeated corner", "pits: [{polygon: [[2, 0.5], [3, 0.5], [3, 1.5], [3, 0.5]]}]\n", 4, "crosses itself"),
    ("zero-area polygon", "pits: [{polygon: [[2, 1], [3, 1], [3.5, 1]]}]\n", 4, "polygon has no area"),
    ("obstacle outside the arena", "obstacles: [{polygon: [[3, 1], [5, 1], [5, 2]], height: 0.2}]\n", 4,
     "point (5, 1) lies outside the arena"),
    ("wall outside the arena", "walls: [[[3, 1], [3, -1]]]\n", 4, "walls[0][1]: point (3, -1) lies outside"),
    ("wall of no length", "walls:\n  - [[3, 1], [3, 2]]\n  - [[2, 1], [2, 1]]\n", 6, "walls[1][1]: point repeats the one before"),
    ("light outside the arena", "lights: [{pos: [9, 9], intensity: 10}]\n", 4, "lights[0].pos: point (9, 9)"),
    ("reach region outside", "expect: {reach: {region: [[3, 1], [9, 1], [9, 2]], within: 5}}\n", 4, "lies outside"),
    ("fault after the end", "faults: [{at: 30, kill: PSC}]\n", 4, "30 s is not before the end of the run"),
    ("keys after the end", "operator: [{at: 25, keys: F}]\n", 4, "is not before the end"),
    ("unknown metric", "expect: {metrics: {nodes.MMC.legs: {eq: 6}, notes.x.nope: {min: 1}}}\n", 4,
     "'notes.x.nope' names no metric"),
    ("unknown top metric", "expect: {metrics: {colisions: {max: 0}}}\n", 4, "names no metric: the metrics has no 'colisions'"),
    ("unknown node metric", "expect: {metrics: {nodes.NOPE.x: {eq: 1}}}\n", 4, "nodes has no 'NOPE'"),
    ("metric below a leaf", "expect: {metrics: {collisions.count: {max: 0}}}\n", 4, "collisions is a single value"),
    ("unknown bus metric", "expect: {metrics: {buses.nope.load: {max: 0.5}}}\n", 4, "buses has no 'nope'"),
    ("coverage not measured", "expect: {metrics: {coverage.share: {min: 0.5}}}\n", 4, "the metrics has no 'coverage'"),
    ("absent node's metric", "robot: {pose: [1, 1.5, 0], absent: [SSC]}\nexpect: {metrics: {nodes.SSC.utterances: {eq: 0}}}",
     4, "node SSC is absent"),
    ("empty metric path", "expect: {metrics: {'a..b': {eq: 1}}}\n", 4, "is not a dotted metric path"),
    ("min above max", "expect: {metrics: {collisions: {min: 3, max: 1}}}\n", 4, "min 3 is above max 1"),
    ("eq with min", "expect: {metrics: {collisions: {min: 0, eq: 1}}}\n", 4, "eq with min or max"),
    ("no bound", "expect: {metrics: {collisions: {}}}\n", 4, "give min, max or eq"),
    ("order of a bad note name", "expect: {order: {first: Escape!, then: stimulus}}\n", 4,
     "expected a debug-port note's name (e.g. escape), got 'Escape!'"),
    ("order without its second note", "expect: {order: {first: escape}}\n", 4, "missing required key 'then'"),
    ("wall band max <= min", "measure: {wall_band: {min: 0.5, max: 0.2}}\n", 4, "max must be above min"),
    ("NaN position", "lights: [{pos: [.nan, 1], intensity: 10}]\n", 4, "'.nan' is not a finite number"),
    ("inf duration", "robot: {pose: [1, 1.5, .inf]}", 3, "is not a finite number"),
    ("float seed", "seed: 2.0\n", 4, "seed: expected an integer, got 2.0"),
    ("bool as number", "duration: true\narena: {size: [4, 3]}\nrobot: {pose: [1, 1.5, 0]}", 1, "expected a number"),
    ("huge coordinate", "lights: [{pos: [1.0e+300, 1], intensity: 10}]\n", 4, "must be <= 100000"),
    ("pose of two values", "robot: {pose: [1, 1.5]}", 3, "needs at least 3 entries"),
    ("include of a list", "include: [[a]]\n", 4, "include: expected a file name"),
]


# A node's own debug figures are typed by its behaviour's debug_metrics() record (e.g. behaviours.mmc.MmcDebug).
# Checked in process (the CLI path of the same check is covered above): (name, expect.metrics line, fragment)
NODE_CASES = [
    ("unknown figure", "{nodes.MMC.legz: {eq: 6}}", "nodes.MMC has no 'legz'"),
    ("figure of the wrong type", "{nodes.MMC.error: {eq: 3}}", "eq 3 is not a value"),
    ("min on a text figure", "{nodes.USRC.status: {min: 1}}", "this metric is not a number"),
    ("below a single figure", "{nodes.SPU.ignored.x: {max: 1}}", "nodes.SPU.ignored is a single value"),
    ("node without debug figures", "{nodes.TPSC.alarms: {max: 0}}", "nodes.TPSC has no 'alarms'"),
    ("text where a flag is", "{nodes.MCP.halted: {eq: maybe}}", "eq 'maybe' is not a value"),
]


@pytest.mark.parametrize("name, metrics, fragment", NODE_CASES, ids=[c[0] for c in NODE_CASES])
def test_node_debug_figures_are_checked_at_load(tmp_path, spec, name, metrics, fragment):
    path = tmp_path / "bad.yaml"
    path.write_text(ROOM + f"expect: {{metrics: {metrics}}}\n")
    with pytest.raises(UserError) as err:
        load_scenario(path, spec)
    text = str(err.value)
    assert len(text.splitlines()) == 1 and text.startswith(f"{path}:4: ") and fragment in text, text


def _scenario(extra: str) -> str:
    if extra.startswith("robot:"):
        return ROOM.replace("robot: {pose: [1, 1.5, 0]}", extra.rstrip("\n")) + "\n"
    if extra.startswith("duration:"):
        return extra + "\n"
    return ROOM + extra


@pytest.mark.parametrize("name, extra, line, fragment", CASES, ids=[c[0] for c in CASES])
def test_meaningless_scenarios_fail_at_load_in_one_line(cli, tmp_path, name, extra, line, fragment):
    path = tmp_path / "bad.yaml"
    path.write_text(_scenario(extra))
    before = snapshot(tmp_path)
    run = cli("sim", "run", str(path), "--out", str(tmp_path / "out"))
    assert_one_line_error(run, f"{path}:{line}: ", fragment)
    assert snapshot(tmp_path) == before


def test_the_room_itself_loads(tmp_path, spec):
    path = tmp_path / "ok.yaml"
    path.write_text(ROOM + "expect: {metrics: {nodes.MMC.legs: {eq: 6}, notes.escape.count: {max: 0},"
                           " motion.TRIPOD.FORWARD.fwd_m: {min: 0.1}, buses.leg.load: {max: 0.5}}}\n")
    assert load_scenario(path, spec).expect.metrics["nodes.MMC.legs"] == {"eq": 6.0}


def test_node_debug_figures_take_typed_bounds(tmp_path, spec):
    """Counts take any number as a bound, text figures text, mappings any key (a leg, a layer, a node)."""
    path = tmp_path / "ok.yaml"
    path.write_text(ROOM + "expect: {metrics: {nodes.MMC.error: {eq: NONE}, nodes.MMC.pits: {max: 0.5},"
                           " nodes.NP3.takeovers.pit: {max: 0}, nodes.MCP.faults.USRC: {eq: 0},"
                           " nodes.PSC.mean_min_v: {min: 4.5}, nodes.NP3.light.ratio: {min: 1}}}\n")
    assert load_scenario(path, spec).expect.metrics["nodes.MMC.pits"] == {"max": 0.5}


class _Inner(TypedDict, total=False):
    ratio: float


class _Record(TypedDict):
    count: int
    name: str | None
    legs: list[int]
    by_leg: dict[str, bool]
    inner: _Inner


def test_schema_of_declares_typed_records_and_refuses_what_json_cannot_hold():
    from sim2d.metrics import schema_of

    assert schema_of(_Record) == {
        "type": "object", "additionalProperties": False, "properties": {
            "count": {"type": "integer"}, "name": {"type": ["string", "null"]},
            "legs": {"type": "array", "items": {"type": "integer"}},
            "by_leg": {"type": "object", "additionalProperties": {"type": "boolean"}},
            "inner": {"type": "object", "additionalProperties": False, "properties": {"ratio": {"type": "number"}}}}}
    for wrong in (tuple[int, int], dict[int, int], set, object):
        with pytest.raises(TypeError, match="not a metric type"):
            schema_of(wrong)


def test_a_concave_obstacle_is_solid_where_its_hull_would_be_wrong(tmp_path):
    """pymunk takes a polygon's convex hull; an L-shape is decomposed so its notch stays free."""
    from sim2d.world import World

    l_shape = [[2, 0.5], [3.5, 0.5], [3.5, 1], [2.5, 1], [2.5, 2.5], [2, 2.5]]
    path = tmp_path / "l.yaml"
    path.write_text(ROOM + f"obstacles: [{{polygon: {l_shape}, height: 0.5}}]\n")
    sc = load_scenario(path)
    assert not is_convex(sc.obstacles[0].polygon)
    world = World(sc)
    assert world.solid_height_at(2.2, 2.0) == 0.5          # inside the L's upright
    assert world.solid_height_at(3.0, 2.0) == 0.0          # the notch: inside the hull, outside the L


def test_the_metrics_of_a_run_have_the_declared_shape(tmp_path, spec):
    """metrics_schema (what expect.metrics paths are checked against) describes what build_metrics really
    produces: a run with every optional section validates, with no undeclared key anywhere."""
    import jsonschema

    from sim2d.metrics import metrics_schema
    from sim2d.sim import Simulation

    path = tmp_path / "all.yaml"
    path.write_text(ROOM.replace("duration: 20", "duration: 3") +
                    "measure: {coverage: {region: [[0, 0], [4, 0], [4, 3], [0, 3]]}, wall_band: {min: 0.1, max: 1}}\n"
                    "sounds: [{at: 1, pos: [3, 2]}]\noperator: [{at: 2, keys: F}]\n"
                    "faults: [{at: 1, until: 2, bus: leg, loss: 0.1}]\n")
    sc = load_scenario(path, spec)
    metrics = Simulation(sc, spec).run().metrics
    schema = metrics_schema(spec, list(sc.measure))
    errors = [f"{list(e.absolute_path)}: {e.message}" for e in jsonschema.Draft202012Validator(schema).iter_errors(metrics)]
    assert errors == []
    assert metrics["coverage"] and metrics["wall_band"] and metrics["notes"] and metrics["motion"]
