"""Feet against the faces of walls and tall obstacles (issue 17/18 leftovers).

A foot in the air that meets a face slides along it and down it: only the part of its move into the face is
refused. Before, the whole move was refused, so a foot pressed into a wall while it was lowered hung there
(no sole contact: a false pit, start_at_wall seeds 9-10) and a foot set down beside a wall stalled on its face
(obstacle_course seed 48: 96.9 servo-seconds at stall current). Thin, tall polygon obstacles count their depth
from the hip's side like walls do, so a foot cannot pass through one either.
"""
from __future__ import annotations

import pytest

from behaviours.kinematics import ik
from sim2d.robot import Robot
from sim2d.robot_params import DEFAULT as P
from sim2d.scenario import load_scenario
from sim2d.world import World

ROOM = "duration: 20\narena: {size: [6, 4]}\nrobot: {pose: [1, 2, 0]}\n"   # leg 2's neutral foot: y = 2.2
WALL = "walls: [[[0.5, 2.24], [1.5, 2.24]]]\n"                                  # its face at y = 2.23
THIN = "obstacles: [{polygon: [[0.5, 2.23], [1.5, 2.23], [1.5, 2.24], [0.5, 2.24]], height: 0.5}]\n"
FACE = 0.23                                                                     # in the body frame


def _robot(write, solid: str) -> Robot:
    sc = load_scenario(write("w.yaml", ROOM + solid))
    return Robot(P, World(sc), sc.start)


def _drive(robot: Robot, leg: int, targets) -> None:
    for target in targets:
        for j, a in enumerate(ik(P, leg, *target)):
            robot.set_joint_target(leg, j + 1, a)
        robot.step(P.dt)


def _lift(robot: Robot, y: float) -> tuple[float, float]:
    """Leg 2's foot lifted 4 cm at body-frame y (a little off the face)."""
    nx, ny = P.neutral_foot(2)
    _drive(robot, 2, [(nx, ny - (ny - y) * k / 20, 0.002 * k) for k in range(1, 21)])
    return nx, ny


@pytest.mark.parametrize("solid", [WALL, THIN], ids=["wall", "thin_obstacle"])
def test_a_foot_lowered_while_pushed_into_a_face_slides_down_it_to_the_ground(write, solid):
    r = _robot(write, solid)
    nx, ny = _lift(r, FACE - 0.01)
    leg = r.legs[2]
    # set down at a point 2 cm beyond the face: the leg pushes into the face all the way down
    _drive(r, 2, [(nx, FACE - 0.01 + 0.03 * k / 30, 0.04 * (1 - k / 30)) for k in range(1, 31)]
           + [(nx, FACE + 0.02, 0.0)] * 10)
    assert leg.contact and leg.anchor is not None                # on the ground at the face's foot: not hanging
    assert 2.0 + FACE - 0.002 <= leg.anchor[1] <= 2.0 + FACE + 1e-6      # and not through it


@pytest.mark.parametrize("solid", [WALL, THIN], ids=["wall", "thin_obstacle"])
def test_a_foot_moving_along_a_face_slides_without_stalling(write, solid):
    r = _robot(write, solid)
    nx, ny = _lift(r, FACE - 0.005)
    leg = r.legs[2]
    # forward 4 cm, aimed from 5 mm off the face to 1 mm into it: it moves along the face, no stall
    _drive(r, 2, [(nx + 0.04 * k / 40, FACE - 0.005 + 0.006 * k / 40, 0.04) for k in range(1, 41)])
    assert leg.world[0] == pytest.approx(1.0 + nx + 0.04, abs=2e-3)
    assert 2.0 + FACE - 0.005 <= leg.world[1] <= 2.0 + FACE + 1e-6
    assert max(j.current for j in leg.joints) < P.servo_stall_a


def test_a_swing_foot_cannot_pass_through_a_thin_obstacle(write):
    """Straight into the thin obstacle's face, past its middle and beyond: stopped at the face (stall current)."""
    r = _robot(write, THIN)
    nx, ny = _lift(r, FACE - 0.002)
    leg = r.legs[2]
    _drive(r, 2, [(nx, FACE - 0.002 + 0.001 * k, 0.04) for k in range(1, 31)])
    assert leg.world[1] <= 2.0 + FACE + 1e-6
    assert r.events.blocked_legs > 0                            # pushed straight at it, the servos stalled
