from __future__ import annotations

import math

import pytest

from sim2d.robot import Robot
from sim2d.robot_params import DEFAULT as P
from sim2d.scenario import load_scenario
from sim2d.sensors import Sensors
from sim2d.world import World

ROOM = "duration: 5\narena: {size: [6, 4], ambient_lux: 10, ambient_temp: 20}\nrobot: {pose: [1, 2, 0]}\n"


def sensors(write, extra="", seed=1):
    sc = load_scenario(write("s.yaml", ROOM + extra))
    world = World(sc)
    return Sensors(world, Robot(P, world, sc.start), seed)


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
