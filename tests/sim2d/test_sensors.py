from __future__ import annotations

import math
from dataclasses import replace

import pytest

from behaviours import tuning as T
from sim2d.robot import Robot
from sim2d.robot_params import DEFAULT as P
from sim2d.scenario import load_scenario
from sim2d.sensors import Sensors
from sim2d.world import World

ROOM = "duration: 5\narena: {size: [6, 4], ambient_lux: 10, ambient_temp: 20}\nrobot: {pose: [1, 2, 0]}\n"


def sensors(write, extra="", seed=1, params=P):
    sc = load_scenario(write("s.yaml", ROOM + extra))
    world = World(sc)
    return Sensors(world, Robot(params, world, sc.start), seed)


def test_sonar_measures_the_wall_and_its_time_of_flight(write, spec):
    s = sensors(write)
    raw, tof = s.usrc_ping(0)                   # wall at x = 6, 5 m ahead
    assert raw == pytest.approx(5.0, abs=0.1)
    assert tof == pytest.approx(2 * 5.0 / 343, rel=0.01)
    raw, _ = s.usrc_ping(180)                  # wall at x = 0, 1 m behind
    assert raw == pytest.approx(1.0, abs=0.1)


def test_light_and_heat_never_block_rays_obstacles_do(write, spec):
    s = sensors(write, "lights: [{pos: [3, 2], intensity: 1000}]\nheat: [{pos: [2.5, 2], temperature: 90, radius: 0.5}]\n")
    assert s.usrc_ping(0)[0] == pytest.approx(5.0, abs=0.1)
    s = sensors(write, "obstacles: [{polygon: [[3, 1], [3.2, 1], [3.2, 3], [3, 3]], height: 0.5}]\n")
    assert s.usrc_ping(0)[0] == pytest.approx(2.0, abs=0.1)


def test_ir_beams_and_whiskers(write, spec):
    wall = "walls: [[[1.2, 0], [1.2, 4]]]\n"     # 4 cm in front of the nose (x = 1.15)
    s = sensors(write, wall)
    left, center, right = s.irrc()
    assert center == pytest.approx(0.04, abs=0.005)   # wall surface at 1.19 (1 cm thick)
    assert left == pytest.approx(0.04 / math.cos(math.radians(15)), abs=0.006)
    assert right == pytest.approx(0.04 / math.cos(math.radians(15)), abs=0.006)
    assert s.whiskers() == (True, True)
    s = sensors(write)
    assert s.irrc() == (None, None, None) and s.whiskers() == (False, False)
    # an obstacle only on the left touches the left whisker only
    s = sensors(write, "obstacles: [{polygon: [[1.16, 2.1], [1.3, 2.1], [1.3, 2.3], [1.16, 2.3]], height: 0.2}]\n")
    assert s.whiskers() == (True, False)


SEEN_AHEAD_M = 0.035     # issue 17: a whisker touch stops the legs ~0.33 s later, 3.3 cm at 10 cm/s
CORNER_WHISKERS = replace(P, whisker_arms=P.whisker_arms[:1])   # docs/decisions.md D18: the outer arms alone


@pytest.mark.parametrize("width", [0.02, 0.03])
@pytest.mark.parametrize("params, blind_ok", [(P, False), (CORNER_WHISKERS, True)], ids=["feelers", "corner-only"])
def test_the_feelers_sense_every_thin_post_in_the_body_lane(write, spec, width, params, blind_ok):
    """docs/decisions.md D18 (scenarios/posts_low.yaml): walking straight at a post 12 cm tall (below the
    sonar head) of the given width, wherever it overlaps the body's lane (its inner edge from 10 cm right to
    8 cm left of the axis, in 5 mm steps), the IR beams or a feeler touch it while its near face is still
    SEEN_AHEAD_M or more ahead of the front face. The outer (corner) arms alone leave 2.6-8 cm either side
    blind: this check finds that lane."""
    half_w, front = P.body_width / 2, P.body_length / 2
    blind = []
    for k in range(int(round((2 * half_w + width) / 0.005))):
        y0 = 2.0 - half_w - width + 0.0025 + 0.005 * k
        x0 = 1.0 + front + 0.12
        post = f"obstacles: [{{polygon: [[{x0}, {y0}], [{x0 + width}, {y0}], [{x0 + width}, {y0 + width}], " \
               f"[{x0}, {y0 + width}]], height: 0.12}}]\n"
        s = sensors(write, post, params=params)
        seen = False
        for step in range(int(round((0.12 - SEEN_AHEAD_M) / 0.005)) + 1):    # the body walks up to the post
            s.robot.pose = (1.0 + 0.005 * step, 2.0, 0.0)
            if any(s.whiskers()) or any(d is not None for d in s.irrc()):
                seen = True
                break
        if not seen:
            blind.append(round(y0 - 2.0, 4))
    if blind_ok:
        assert len(blind) >= 10, f"the corner arms alone leave only {blind} blind"
    else:
        assert blind == [], f"posts with their inner edge this far left of the axis (m) are not sensed: {blind}"


WITHOUT_SIDE_WIRE = replace(P, whisker_arms=(P.whisker_arms[0], P.whisker_arms[2]))   # D18 before: two wires


@pytest.mark.parametrize("width", [0.02, 0.03])
@pytest.mark.parametrize("params, blind_ok", [(P, False), (WITHOUT_SIDE_WIRE, True)], ids=["feelers", "no-side-wire"])
def test_the_feelers_sense_every_thin_post_beside_the_body_a_turn_on_the_spot_sweeps(write, spec, width, params,
                                                                                       blind_ok):
    """docs/decisions.md D18 (scenarios/open/posts_field.yaml seed 11): a turn on the spot sweeps the body's
    sides out to its corners' circle (17 cm round the centre), so a post walked past beside the body closer to
    the axis than that is met by the next turn. Walking straight past a post 12 cm tall (below the sonar head)
    whose inner edge lies 8-17 cm beside the axis (5 mm steps, either side), a feeler touches it before the
    front face has passed it. Without the side wire (62 deg) the outer wire at 25 deg reached 12.2 cm: posts
    12.5-17 cm out were never felt (posts_field seed 11: walked past 15 cm out, the explore task's turn met
    it, 17 contacts)."""
    half_w, front = P.body_width / 2, P.body_length / 2
    corner = math.hypot(front, half_w)
    blind = []
    for side in (1.0, -1.0):
        for k in range(int(round((corner - half_w) / 0.005)) + 1):
            inner = half_w + 0.005 * k
            y0 = 2.0 + inner if side > 0 else 2.0 - inner - width
            x0 = 1.0 + front + 0.12
            post = f"obstacles: [{{polygon: [[{x0}, {y0}], [{x0 + width}, {y0}], [{x0 + width}, {y0 + width}], " \
                   f"[{x0}, {y0 + width}]], height: 0.12}}]\n"
            s = sensors(write, post, params=params)
            steps = int(round((0.12 + width) / 0.005)) + 1          # until the face is level with its far side
            if not any(_touched(s, 1.0 + 0.005 * step) for step in range(steps)):
                blind.append(round(side * inner, 4))
    if blind_ok:
        assert len(blind) >= 10, f"without the side wire only {blind} are blind"
    else:
        assert blind == [], f"posts with their inner edge this far beside the axis (m, + left) are not felt: {blind}"


def _touched(s: Sensors, x: float) -> bool:
    s.robot.pose = (x, 2.0, 0.0)
    return any(s.whiskers())


def test_light_falls_with_distance_and_is_shaded_by_walls(write, spec):
    lit = "lights: [{pos: [2, 2], intensity: 990}]\n"          # 990 cd at 1 m + 10 lx ambient = 1000 lx
    assert sensors(write, lit).lsc() == pytest.approx(1000, rel=0.1)
    shaded = lit + "walls: [[[1.5, 0], [1.5, 4]]]\n"
    assert sensors(write, shaded).lsc() == pytest.approx(10, rel=0.1)   # only the ambient 10 lx


def test_temperature_channels_and_inclination(write, spec):
    hot = "heat: [{pos: [1.2, 2], temperature: 80, radius: 0.2}]\n"
    t = sensors(write, hot).tsc()
    assert len(t) == 8 and t[0] == max(t) and t[0] > 60 and t[4] < 25   # channel 0 faces the source
    slope = "slopes: [{polygon: [[0, 0], [6, 0], [6, 4], [0, 4]], incline_x: 12}]\n"
    lon, tr = sensors(write, slope).isc()
    assert lon == pytest.approx(12, abs=3) and abs(tr) <= 3
    assert lon % 3 == 0 and tr % 3 == 0                  # seed 3.2.14: the sensor resolves 3 degree steps
    steep = "slopes: [{polygon: [[0, 0], [6, 0], [6, 4], [0, 4]], incline_x: 75}]\n"
    assert sensors(write, steep).isc()[0] == 60          # seed 3.2.14: range -60..60 degrees


def test_noise_streams_are_independent(write, spec):
    a = sensors(write, seed=7)
    b = sensors(write, seed=7)
    for _ in range(5):
        b.tsc()                                    # draws from another stream only
    assert [a.usrc_ping(0)[0] for _ in range(20)] == [b.usrc_ping(0)[0] for _ in range(20)]
    c = sensors(write, seed=8)
    assert [a.usrc_ping(0)[0] for _ in range(50)] != [c.usrc_ping(0)[0] for _ in range(50)]


def test_the_np3_knows_the_sensor_mounts_the_simulated_body_has():
    """The NP3 cannot import the simulator (layers), so it keeps its own copy of the mounts (behaviours.tuning):
    an echo from a whisker touch or an IR beam is placed where that copy says. Moving a mount in
    sim2d.robot_params (docs/decisions.md D18) without the copy would misplace every such echo silently."""
    assert T.NP3_BODY_FRONT_M == pytest.approx(P.body_length / 2)
    assert len(T.NP3_WHISKER_ARMS) == len(P.whisker_arms)
    for known, built in zip(T.NP3_WHISKER_ARMS, P.whisker_arms):
        assert len(known) == len(built)
        for k, b in zip(known, built):
            assert (k.x, k.y) == (pytest.approx(b.x, abs=1e-4), pytest.approx(b.y, abs=1e-4))
    assert sorted(P.ir_beams_deg) == pytest.approx([-T.NP3_IR_BEAM_DEG, 0.0, T.NP3_IR_BEAM_DEG])
