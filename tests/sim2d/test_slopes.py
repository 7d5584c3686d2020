"""Slopes met at any angle (seed 3.2.14, issue 17): the tilt reflex reads the slope's own inclination from both
ISC axes, so a too-steep slope is refused at 0, 30, 45 and 60 degrees to its edge and a passable one is climbed."""
from __future__ import annotations

import pytest

from sim2d.scenario import load_scenario
from sim2d.sim import Simulation

EDGE_X = 2.5          # the slope rises along +x beyond this line

WORLD = """arena: {{size: [6, 4]}}
duration: 32
robot: {{pose: [2.0, 0.7, {heading}], task: forward}}
slopes: [{{polygon: [[{edge}, 0], [6, 0], [6, 4], [{edge}, 4]], incline_x: {incline}}}]
"""


def walk(write, spec, heading: float, incline: float):
    sc = load_scenario(write("slope.yaml", WORLD.format(heading=heading, edge=EDGE_X, incline=incline)), spec)
    sim = Simulation(sc, spec)
    r = sim.run()
    return r.metrics, max(x for _t, x, _y, _th in r.poses)


@pytest.mark.parametrize("heading", [0, 30, 45, 60])
def test_a_too_steep_slope_is_refused_from_any_angle(write, spec, heading):
    m, furthest = walk(write, spec, heading, 35.0)
    assert m["nodes"]["NP3"]["takeovers"].get("tilt", 0) >= 1
    assert furthest < EDGE_X + 0.3, f"the body centre got {furthest - EDGE_X:.2f} m onto the slope"
    assert not m["fell"] and m["collisions"] == 0


@pytest.mark.parametrize("heading", [0, 30, 45, 60])
def test_a_passable_slope_is_climbed_from_any_angle(write, spec, heading):
    m, furthest = walk(write, spec, heading, 15.0)
    assert m["nodes"]["NP3"]["takeovers"].get("tilt", 0) == 0
    assert furthest > EDGE_X + 0.5
