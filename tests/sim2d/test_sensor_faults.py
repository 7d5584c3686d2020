"""Scenario sensor faults (`faults: - {sensor: IRRC, noise: 0.03}`) and the battery knobs: schema, physics, run."""
from __future__ import annotations

import statistics

import pytest

from arachnae.errors import UserError
from sim2d.robot import Robot
from sim2d.robot_params import DEFAULT as P
from sim2d.scenario import load_scenario
from sim2d.sensors import Sensors
from sim2d.sim import Simulation
from sim2d.world import World

ROOM = "duration: 5\narena: {size: [6, 4], ambient_lux: 10, ambient_temp: 20}\nrobot: {pose: [1, 2, 0]}\n"


@pytest.mark.parametrize("faults, line, fragment", [
    ("  - {at: 1, sensor: IRRC}\n", 5, "a sensor fault needs noise > 0"),
    ("  - {at: 1, kill: IRRC, noise: 0.1}\n", 5, "noise belongs to a sensor fault"),
    ("  - {at: 1, sensor: TPSC, noise: 0.1}\n", 5, "'TPSC' is not one of"),
    ("  - {at: 1, sensor: IRRC, noise: -1}\n", 5, "noise: must be >= 0"),
    ("  - {at: 1, sensor: IRRC, kill: USRC, noise: 0.1}\n", 5, "exactly one of kill, mute, bus, sensor, request, collide"),
    ("  - {at: 4, until: 2, sensor: USRC, noise: 0.1}\n", 5, "until must be after at"),
])
def test_bad_sensor_faults_are_one_line_errors(write, spec, faults, line, fragment):
    p = write("bad.yaml", ROOM + "faults:\n" + faults)
    with pytest.raises(UserError) as exc:
        load_scenario(p, spec)
    msg = str(exc.value)
    assert msg.startswith(f"{p}:{line}: ") and fragment in msg and "\n" not in msg, msg


@pytest.mark.parametrize("robot, fragment", [
    ("battery_charge: 1.5", "battery_charge: must be <= 1.0"),
    ("battery_ah: 0", "battery_ah: must be > 0"),
])
def test_bad_battery_knobs(write, spec, robot, fragment):
    p = write("bad.yaml", ROOM.replace("robot: {pose: [1, 2, 0]}", "robot: {pose: [1, 2, 0], " + robot + "}"))
    with pytest.raises(UserError, match=fragment):
        load_scenario(p, spec)


def test_sensor_fault_is_loaded(write, spec):
    sc = load_scenario(write("s.yaml", ROOM + "faults:\n  - {at: 2, until: 4, sensor: IRRC, noise: 0.03}\n"), spec)
    (f,) = sc.faults
    assert (f.kind, f.node, f.noise, f.at, f.until) == ("sensor", "IRRC", 0.03, 2.0, 4.0)


def sensors(write, extra=""):
    sc = load_scenario(write("s.yaml", ROOM + extra))
    world = World(sc)
    return Sensors(world, Robot(P, world, sc.start), 1)


def test_a_noisy_ir_sensor_spreads_and_makes_up_echoes(write):
    s = sensors(write, "walls: [[[1.2, 0], [1.2, 4]]]\n")   # 4 cm in front of the nose
    clean = [s.irrc()[1] for _ in range(50)]
    assert statistics.pstdev(clean) < 0.005
    s.set_fault("IRRC", 0.03)
    noisy = [s.irrc()[1] for _ in range(200)]
    assert statistics.pstdev([d for d in noisy if d is not None]) > 0.015
    free = sensors(write)                                   # nothing in range: no echo ...
    assert all(d is None for _ in range(20) for d in free.irrc())
    free.set_fault("IRRC", 0.03)
    assert any(d is not None for _ in range(50) for d in free.irrc())   # ... until the sensor is faulty
    free.set_fault("IRRC", 0.0)
    assert all(d is None for _ in range(20) for d in free.irrc())        # `until`: healthy again


def test_sensor_fault_draws_from_its_own_stream(write):
    """Adding a fault never changes the numbers another sensor sees (sim2d.rng)."""
    a, b = sensors(write), sensors(write)
    b.set_fault("USRC", 0.5)
    assert [a.psc() for _ in range(10)] == [b.psc() for _ in range(10)]
    assert [a.usrc_ping(0)[0] for _ in range(5)] != [b.usrc_ping(0)[0] for _ in range(5)]


def test_the_battery_knobs_set_the_charge_and_the_capacity(write, spec):
    sc = load_scenario(write("s.yaml", ROOM.replace("robot: {pose: [1, 2, 0]}",
                                                     "robot: {pose: [1, 2, 0], battery_charge: 0.5, battery_ah: 0.1}")),
                       spec)
    sim = Simulation(sc, spec)
    assert sim.params.battery_ah == 0.1
    full, empty = P.battery_full_v, P.battery_empty_v
    assert sim.robot.battery_voltage() == pytest.approx(empty + 0.5 * (full - empty))


def test_a_sensor_fault_is_applied_at_its_time_and_noted(write, spec):
    sc = load_scenario(write("s.yaml", ROOM.replace("duration: 5", "duration: 1.5")
                             + "faults:\n  - {at: 0.5, until: 1.0, sensor: PSC, noise: 0.2}\n"), spec)
    sim = Simulation(sc, spec)
    seen = []
    sim.sched.at(0.7, lambda: seen.append(dict(sim.sensors.fault_noise)))
    result = sim.run()
    assert seen == [{"psc": 0.2}] and sim.sensors.fault_noise == {"psc": 0.0}
    assert result.metrics["notes"]["fault_injected"]["first_s"] == 0.5
