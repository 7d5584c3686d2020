from __future__ import annotations

import math

import pytest

from arachnae.errors import UserError
from sim2d.scenario import load_scenario

BASE = """\
duration: 10
arena: {size: [4, 3]}
robot: {pose: [1, 1, 90]}
"""


def test_minimal_scenario_defaults(write):
    sc = load_scenario(write("s.yaml", BASE))
    assert sc.duration == 10.0 and sc.size == (4.0, 3.0)
    assert sc.start[2] == pytest.approx(math.pi / 2)
    assert sc.task == "forward" and sc.absent == () and sc.boundary_walls


def test_include_concatenates_lists_and_scenario_wins(write):
    write("common/room.yaml", "arena: {size: [8, 8], ambient_lux: 5}\nwalls: [[[0, 2.5], [2, 2.5]]]\nduration: 99\n")
    p = write("s.yaml", "include: common/room.yaml\n" + BASE + "walls: [[[3, 0], [3, 2]]]\n")
    sc = load_scenario(p)
    assert sc.duration == 10.0                     # the including file wins
    assert sc.size == (4.0, 3.0) and sc.ambient_lux == 5.0   # mapping keys merge key by key
    assert len(sc.walls) == 2                      # list keys concatenate


@pytest.mark.parametrize("extra, line, fragment", [
    ("bogus: 1\n", 4, "unknown key 'bogus'"),
    ("obstacles:\n  - {polygon: [[0,0],[1,0],[1,1]], height: -2}\n", 5, "height: must be > 0"),
    ("obstacles:\n  - {polygon: [[0,0],[1,0]], height: 1}\n", 5, "at least 3"),
    ("faults:\n  - {at: 1, kill: NOPE}\n", 5, "'NOPE' is not one of"),
    ("faults:\n  - {at: 1, bus: leg}\n", 5, "needs loss, corrupt or delay"),
    ("faults:\n  - {at: 5, until: 2, mute: PSC}\n", 5, "until must be after at"),
    ("expect: {post: FINE}\n", 4, "'FINE' is not one of"),
    ("seed: 1.5\n", 4, "expected an integer"),
    ("contention: {bus: sensor, stimulus: sneeze}\n", 4, "'sneeze' is not one of"),
    ("contention: {bus: nobus, stimulus: whisker}\n", 4, "'nobus' is not one of"),
])
def test_errors_name_file_and_line(write, spec, extra, line, fragment):
    p = write("bad.yaml", BASE + extra)
    with pytest.raises(UserError) as exc:
        load_scenario(p, spec)
    msg = str(exc.value)
    assert msg.startswith(f"{p}:{line}: "), msg
    assert fragment in msg and "\n" not in msg


def test_contention_is_read(write, spec):
    sc = load_scenario(write("s.yaml", BASE + "contention: {bus: sensor, stimulus: whisker}\n"), spec)
    assert (sc.contention.bus, sc.contention.stimulus) == ("sensor", "whisker")
    assert load_scenario(write("t.yaml", BASE), spec).contention is None


def test_error_in_included_file_names_that_file(write):
    write("inc.yaml", "lights:\n  - {pos: [1, 1], intensity: zero}\n")
    p = write("s.yaml", "include: inc.yaml\n" + BASE)
    with pytest.raises(UserError, match=r"inc\.yaml:2: lights\[0\]\.intensity: expected a number"):
        load_scenario(p)


def test_include_cycle_and_missing_include(write):
    write("a.yaml", "include: b.yaml\n" + BASE)
    write("b.yaml", "include: a.yaml\n")
    with pytest.raises(UserError, match="include cycle"):
        load_scenario(write("a.yaml", "include: b.yaml\n" + BASE))
    with pytest.raises(UserError, match=r"s\.yaml:1: included file 'nope.yaml' not found"):
        load_scenario(write("s.yaml", "include: nope.yaml\n" + BASE))


def test_missing_required_key_and_bad_yaml(write):
    with pytest.raises(UserError, match="missing required key 'robot'"):
        load_scenario(write("s.yaml", "duration: 1\narena: {size: [1, 1]}\n"))
    with pytest.raises(UserError) as err:          # every missing key, once, in one line (arachnae.validation)
        load_scenario(write("s.yaml", "duration: 1\n"))
    assert str(err.value).endswith("s.yaml:1: (top level): missing required keys 'arena', 'robot'"), err.value
    with pytest.raises(UserError, match=r"s\.yaml:2: .*invalid YAML"):
        load_scenario(write("s.yaml", "duration: 1\narena: {size: [1, 1]}}\nrobot: {}\n"))


def test_start_outside_arena_is_rejected(write):
    with pytest.raises(UserError, match=r":3: robot.pose: start pose \(9, 1\) lies outside"):
        load_scenario(write("s.yaml", BASE.replace("[1, 1, 90]", "[9, 1, 0]")))


def test_shipped_scenarios_load(spec):
    from pathlib import Path
    root = Path(__file__).resolve().parents[2] / "scenarios"
    files = sorted(p for p in root.glob("*.yaml"))
    assert len(files) >= 6
    for p in files:
        load_scenario(p, spec)
