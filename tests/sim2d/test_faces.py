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


LOW_BAR = "obstacles: [{polygon: [[0.5, 2.23], [1.5, 2.23], [1.5, 2.29], [0.5, 2.29]], height: 0.04}]\n"


def test_a_swing_foot_the_body_carried_into_a_low_bars_side_stays_stalled_at_its_face(write):
    """A foot 2 cm up beside a 4 cm bar, carried 0.5 mm into the bar's outline by the body, then pushed on into it.

    It is below the bar's top and came in sideways, so it is at the face, not on top: it stays stalled step
    after step (before, it counted as standing on the bar after one stalled 10 ms step, too short for any LCP
    poll: fault_battery_and_leg's blocked leg went unreported)."""
    r = _robot(write, LOW_BAR)
    nx, _ = _lift(r, FACE - 0.001)                                 # 1 mm off the face, foot 4 cm up
    leg = r.legs[2]
    _drive(r, 2, [(nx, FACE - 0.001, 0.04 - 0.001 * k) for k in range(1, 21)])   # down to 2 cm, below the top
    stance = {i: P.neutral_foot(i) for i in r.legs if i != 2}
    for k in range(1, 16):                                         # the stance feet carry the body 1.5 mm to +y
        for i, (sx, sy) in stance.items():
            for j, a in enumerate(ik(P, i, sx, sy - 0.0001 * k, 0.0)):
                r.set_joint_target(i, j + 1, a)
        r.step(P.dt)
    assert r.pose[1] == pytest.approx(2.0015, abs=2e-4)
    assert 0.0 < leg.world[1] - (2.0 + FACE) < 0.001              # the foot is a fraction of a mm inside the bar
    stalled = 0
    for j, a in enumerate(ik(P, 2, nx, leg.foot[1] + 0.001, 0.02)):   # the swing pushes level, 1 mm on into it
        r.set_joint_target(2, j + 1, a)
    for _ in range(10):
        r.step(P.dt)
        assert not leg.contact                                     # not standing on the bar's top
        stalled += max(j.current for j in leg.joints) >= P.servo_stall_a
    assert stalled == 10                                           # stalled at every step: an LCP poll sees it
    assert leg.world[1] - (2.0 + FACE) < 0.001                     # and not pushed on into the bar


def test_a_foot_set_down_from_above_just_inside_a_low_bars_edge_stands_on_its_top(write):
    """The face skin is for feet that came in sideways below the top: one lowered onto the bar, 3 mm in from its
    edge (inside the skin), stands on it."""
    r = _robot(write, LOW_BAR)
    nx, _ = _lift(r, FACE - 0.005)
    leg = r.legs[2]
    _drive(r, 2, [(nx, FACE - 0.005, 0.04 + 0.001 * k) for k in range(1, 11)]          # up to 5 cm
           + [(nx, FACE - 0.005 + 0.0004 * k, 0.05) for k in range(1, 21)]            # over the bar, 3 mm in
           + [(nx, FACE + 0.003, 0.05 - 0.0005 * k) for k in range(1, 21)])           # and down onto it
    assert leg.contact and leg.anchor is not None
    assert leg.foot[2] == pytest.approx(0.04, abs=0.0025)
    assert leg.anchor[1] == pytest.approx(2.0 + FACE + 0.003, abs=5e-4)
