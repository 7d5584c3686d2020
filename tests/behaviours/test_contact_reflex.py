"""The contact reflex switched on next to walls (issue 17 item 5, seed 5.1.2, 5.2): whatever the wall's angle,
or in a corner, its manoeuvre never sweeps the body into a wall and leaves the robot walking away from each.

A small world of straight walls in the robot's start frame: the IR beams and the whiskers are cast onto
them, the manoeuvre the reflex plans is followed with the speeds the NP3 assumes, and the body's corners
are checked at every step."""
from __future__ import annotations

import math
from typing import NamedTuple

import pytest

from arachnae_proto.enums import MovCmd
from behaviours.np3_layers import ContactModule, Tuning, WhiskerEvent, contact_trigger, velocity
from behaviours import tuning as T
from behaviours.geometry import mirrored
from sim2d.robot_params import DEFAULT as P

TUNING = Tuning()


class Wall(NamedTuple):
    normal_deg: float      # direction from the robot towards the wall, start frame (0 = straight ahead)
    dist_m: float          # the start pose's distance to it


def corners(x: float, y: float, th: float) -> list[tuple[float, float]]:
    hl, hw = P.body_length / 2, P.body_width / 2
    c, s = math.cos(th), math.sin(th)
    return [(x + bx * c - by * s, y + bx * s + by * c) for bx in (hl, -hl) for by in (hw, -hw)]


def depth(p: tuple[float, float], w: Wall) -> float:
    """How far the point lies beyond the wall (> 0: inside it)."""
    a = math.radians(w.normal_deg)
    return p[0] * math.cos(a) + p[1] * math.sin(a) - w.dist_m


def walls_at(normals_deg: tuple[float, ...], gap_m: float) -> list[Wall]:
    """Walls with these normals, each gap_m from the body's nearest corner at the start pose."""
    return [Wall(n, max(depth(c, Wall(n, 0.0)) for c in corners(0.0, 0.0, 0.0)) + gap_m) for n in normals_deg]


def ray(origin: tuple[float, float], deg: float, reach: float, walls: list[Wall]) -> float | None:
    ux, uy = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    hits = []
    for w in walls:
        a = math.radians(w.normal_deg)
        towards = ux * math.cos(a) + uy * math.sin(a)
        if towards > 1e-9:
            s = -depth(origin, w) / towards
            if 0.0 <= s <= reach:
                hits.append(s)
    return min(hits, default=None)


def sonar_echoes(walls: list[Wall]) -> tuple:
    """What a sonar sweep from the body centre leaves in the echo memory: one point every 30 deg where a beam
    meets a wall within 0.5 m (start frame = the dead-reckoned frame, pose (0, 0, 0))."""
    out = []
    for deg in range(-180, 180, 30):
        d = ray((0.0, 0.0), deg, 0.5, walls)
        if d is not None:
            out.append((d * math.cos(math.radians(deg)), d * math.sin(math.radians(deg)), float(deg), 0.0))
    return tuple(out)


def sensed(walls: list[Wall]) -> dict:
    """seed 3.2.12, 3.2.13: the three IR beams (10 cm) and the two whiskers at the start pose, and the echoes."""
    front = (P.body_length / 2, 0.0)
    ir = tuple(ray(front, deg, P.ir_range, walls) for deg in P.ir_beams_deg)
    left, right = (any(ray(a, math.degrees(math.atan2(b.y - a.y, b.x - a.x)), math.dist(a, b), walls) is not None
                       for arm in arms for a, b in zip(arm, arm[1:]))
                   for arms in (P.whisker_arms, mirrored(P.whisker_arms)))
    return {"ir": ir, "whisker": (1, left, right, 0.0), "pose": (0.0, 0.0, 0.0), "echoes": sonar_echoes(walls)}


def follow(steps, walls: list[Wall], dt: float = 0.02) -> tuple[float, float]:
    """Follow the plan from the start pose; (the deepest any body corner went into a wall, final heading)."""
    x = y = th = 0.0
    worst = -math.inf
    for duration, cmd in steps:
        vx, vy, w = velocity(cmd, TUNING)
        for _ in range(int(round(duration / dt))):
            x += (vx * math.cos(th) - vy * math.sin(th)) * dt
            y += (vx * math.sin(th) + vy * math.cos(th)) * dt
            th += w * dt
            worst = max(worst, max(depth(c, wall) for c in corners(x, y, th) for wall in walls))
    return worst, th


CASES = {
    "facing a wall": ((0.0,), 0.03),
    "wall 30 deg to the left": ((30.0,), 0.03),
    "wall 30 deg to the right": ((-30.0,), 0.03),
    "wall 60 deg to the right": ((-60.0,), 0.03),
    "pressed into a corner": ((45.0, -45.0), 0.03),
    "corner, one wall square ahead": ((0.0, 90.0), 0.03),
}


@pytest.mark.parametrize("name", CASES)
def test_switched_on_next_to_walls_the_reflex_turns_away_without_touching(name):
    normals, gap = CASES[name]
    walls = walls_at(normals, gap)
    seen = sensed(walls)
    assert seen["whisker"][1] or seen["whisker"][2] or any(d is not None for d in seen["ir"])   # a real contact
    steps = contact_trigger(TUNING)(seen, 0.0)
    assert steps, f"{name}: no reaction to {seen}"
    worst, heading = follow(steps, walls)
    assert worst < 0.0, f"{name}: a body corner went {worst:.3f} m into a wall"
    for w in walls:                                     # every wall behind the robot's side: it walks away
        off = abs((math.degrees(heading) - w.normal_deg + 180.0) % 360.0 - 180.0)
        assert off >= 90.0 + T.NP3_CONTACT_CLEAR_DEG / 2, f"{name}: heading {math.degrees(heading):.0f} deg, wall {w}"


def test_a_touch_the_ir_reports_a_poll_later_is_escaped_from_what_the_beams_see():
    """The TPSC reports at once, the IRRC when polled: the right whisker's touch of a block nearly square ahead
    arrives while the beams still read nothing (clutter seed 3). The guess (the surface 60 deg aside) turns
    only 50 deg without backing off and leaves the face ahead of the robot's side; once the beams report
    (0.2 s later) the escape is planned again from them: back off, turn until the face is behind the side."""
    walls = walls_at((-10.0,), 0.06)                   # the right outer wire's tip reaches 6.8 cm past the corner
    seen = sensed(walls)
    assert seen["whisker"][1:3] == (False, True) and seen["ir"][1] is not None     # the case: right whisker, IR ahead
    blind = {**seen, "ir": (None, None, None)}
    guess = contact_trigger(TUNING)(blind, 0.0)
    _worst, heading = follow(guess, walls)
    off = abs((math.degrees(heading) - walls[0].normal_deg + 180.0) % 360.0 - 180.0)
    assert off < 90.0 + T.NP3_CONTACT_CLEAR_DEG / 2           # the guess alone: the face still ahead of the side
    reflex = ContactModule(TUNING)
    first = reflex.step(blind, 0.0)["move"]
    assert first is not None
    later = 0.2
    reflex.step(seen, later)
    steps = [(later, first), *reflex.plan.steps]
    worst, heading = follow(steps, walls)
    assert worst < 0.0, f"a body corner went {worst:.3f} m into the wall"
    off = abs((math.degrees(heading) - walls[0].normal_deg + 180.0) % 360.0 - 180.0)
    assert off >= 90.0 + T.NP3_CONTACT_CLEAR_DEG / 2, f"heading {math.degrees(heading):.0f} deg: walks back into it"
    reflex.step(seen, later + 0.1)                             # re-planned once: the IR seeing it again changes nothing
    assert reflex.plan.steps == steps[1:]


def test_a_touch_the_ir_reports_after_the_hold_keeps_its_escape():
    """Only the beams' report of the touch itself re-plans: an echo more than one reflex hold later is
    something the escape has turned to since, and the escape runs on."""
    walls = walls_at((-10.0,), 0.06)
    seen = sensed(walls)
    blind = {**seen, "ir": (None, None, None)}
    reflex = ContactModule(TUNING)
    reflex.step(blind, 0.0)
    plan = reflex.plan
    reflex.step(seen, TUNING.reflex_hold_s + 0.1)
    assert reflex.plan is plan


def test_a_wall_alongside_that_touched_an_outer_wire_is_stepped_away_from_not_turned_from():
    """docs/decisions.md D18 (corridor_narrow): the node found a wall alongside where the right outer wire
    reaches (sonar memory, IR clear: WhiskerEvent.alongside). Turning from it on the 60 deg guess faced the body
    at the corridor's other wall; the escape is a sidestep away, the heading kept, no corner into the wall."""
    walls = walls_at((-90.0,), 0.09)                    # the right outer wire's tip reaches 9.7 cm past the side
    seen = sensed(walls)
    assert seen["whisker"][1:3] == (False, True) and seen["ir"] == (None, None, None)
    guessed = contact_trigger(TUNING)(seen, 0.0)
    assert any(cmd in (MovCmd.TURN_LEFT, MovCmd.TURN_RIGHT) for _d, cmd in guessed)   # not known: the guess
    steps = contact_trigger(TUNING)({**seen, "whisker": WhiskerEvent(1, False, True, 0.0, alongside=True)}, 0.0)
    assert [cmd for _d, cmd in steps] == [MovCmd.SIDESTEP_LEFT]
    worst, heading = follow(steps, walls)
    assert worst < -0.08 and heading == 0.0


def test_a_wall_alongside_closing_in_ahead_is_stepped_from_then_walked_parallel_to():
    """The same touch with the wall 10 deg across the heading (the body yawed towards it: a sidestep alone
    met it again and again, corridor_narrow seed 2): after the sidestep the escape turns away until the heading
    is parallel to the wall the remembered echoes show, so walking on keeps the distance."""
    walls = walls_at((-80.0,), 0.09)                    # a wall on the right, nearer ahead than behind
    seen = sensed(walls)
    assert seen["whisker"][1:3] == (False, True) and seen["ir"] == (None, None, None)
    steps = contact_trigger(TUNING)({**seen, "whisker": WhiskerEvent(1, False, True, 0.0, alongside=True)}, 0.0)
    assert [cmd for _d, cmd in steps] == [MovCmd.SIDESTEP_LEFT, MovCmd.TURN_LEFT]
    worst, heading = follow(steps, walls)
    assert worst < -0.08 and math.degrees(heading) == pytest.approx(10.0, abs=3.0)
