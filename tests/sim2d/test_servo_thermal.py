"""Simulated servo windings warm with their current and cool to the air (seed 3.2.10: servo temperature)."""
from __future__ import annotations

import pytest

from sim2d.robot import Robot
from sim2d.robot_params import DEFAULT as P
from sim2d.scenario import load_scenario
from sim2d.world import World

ROOM = "duration: 20\narena: {size: [6, 4], ambient_temp: 25}\nrobot: {pose: [3, 2, 0]}\n"


def run(robot: Robot, amps: float, seconds: float) -> float:
    j = robot.legs[1].joints[0]
    for _ in range(round(seconds / P.dt)):
        j.current = amps
        robot.warm_servos(P.dt)
    return j.temperature


def test_a_stalled_servo_overheats_a_moving_one_stays_warm_and_both_cool_to_the_air(write):
    sc = load_scenario(write("s.yaml", ROOM))
    robot = Robot(P, World(sc), sc.start)
    assert robot.legs[1].joints[0].temperature == pytest.approx(25.0)      # starts at the air temperature
    hot = run(robot, P.servo_stall_a, 20.0)
    assert hot > 70.0                                   # seed 6.1 stall current: past the JAC's limit in ~14 s
    cool = run(robot, 0.0, 300.0)
    assert cool == pytest.approx(25.0, abs=1.0)         # five time constants later: back at the air
    warm = run(robot, P.servo_move_a, 600.0)            # walking all the time: a few kelvin above the air
    assert 27.0 < warm < 40.0


def test_the_winding_temperature_reaches_the_jac(write):
    from sim2d.hardware import NodeHardware

    class Node:
        leg, joint, short = 1, 1, "JAC(1,1)"

    class Sim:
        def __init__(self, robot):
            self.robot, self.sched, self.sensors = robot, None, None
    sc = load_scenario(write("s.yaml", ROOM))
    robot = Robot(P, World(sc), sc.start)
    robot.legs[1].joints[0].temperature = 66.5
    hw = NodeHardware(Sim(robot), Node())               # type: ignore[arg-type]
    assert hw.servo_state().temperature == 66.5
    hw.set_servo_drive(None)                             # no pulses: limp
    assert not robot.legs[1].joints[0].powered
