"""LCP (seed 3.2.10, 6.1): swing profile, blocked-leg reflex, no ground, JAC faults and over-temperature."""
from __future__ import annotations

import math

import pytest

from arachnae_proto import messages as M
from arachnae_proto.enums import JointFlags, LegFlags, LegPhase, OrderStatus

from behaviours import tuning as T
from behaviours.geometry import DEFAULT_GEOMETRY as G
from behaviours.kinematics import fk, ik, swing_point
from behaviours.units import quantizer
from tests.behaviours.rig import Rig
from tests.behaviours.test_lcp_kinematics import JACS, commanded, jacs_answer, jacs_at_set_point

MMC, LCP1 = 0x03, 0x21
_FB_DEG = quantizer(M.JointFeedback, "angle")


def answer(current_ma: int = 50, temp: int = 31, flags: int = 0, silent: tuple = ()):
    def respond(f):
        if isinstance(f.message, M.JointPoll):
            if f.dst in silent:
                return []
            return [(f.dst, M.JointFeedback(angle=0, speed=0, current=current_ma, temperature=temp, flags=flags))]
        return jacs_answer(f)
    return respond


def report(rig: Rig, at: float) -> M.LegReport:
    rig.inject(at, MMC, M.LegPoll())
    rig.run(at + 0.05)
    return rig.frames(M.LegReport)[-1][1].message


def status(rig: Rig, at: float) -> int:
    rig.inject(at, MMC, M.StatusReq())
    rig.run(at + 0.05)
    return rig.frames(M.StatusAckOrder, MMC)[-1][1].message.status


def swing(rig: Rig, at: float, x: float = 40, y: float = 120, z: float = 30, ms: int = 1000) -> None:
    rig.inject(at, MMC, M.LegTarget.from_phys(phase=int(LegPhase.SWING), x=x, y=y, z=z, duration=ms))


def stance(rig: Rig, at: float, x: float = -40, y: float = 120, ms: int = 1000) -> None:
    rig.inject(at, MMC, M.LegTarget.from_phys(phase=int(LegPhase.STANCE), x=x, y=y, z=0, duration=ms))


def test_swing_point_lifts_straight_up_carries_over_and_lowers_straight_down():
    start, end, lift, edge = (0.0, 0.2, 0.0), (0.08, 0.2), 0.03, 0.25
    pts = [swing_point(start, end, lift, i / 100, edge) for i in range(101)]
    for s, (x, y, z) in zip((i / 100 for i in range(101)), pts):
        if s <= edge:
            assert (x, y) == (0.0, 0.2)                       # lift-off: vertical
        elif s < 1 - edge:
            assert z == pytest.approx(lift)                    # transfer at full height
        else:
            assert (x, y) == end                               # touch-down: vertical
    assert pts[0][2] == 0.0 and pts[-1][2] == pytest.approx(0.0) and pts[50][0] == pytest.approx(0.04)
    # a swing re-planned in the air needs no second lift-off
    mid = swing_point((0.02, 0.2, 0.03), end, lift, 0.01, edge)
    assert mid[2] == pytest.approx(0.03) and mid[0] > 0.02


def test_lcp_swing_profile_on_the_wire(spec):
    rig = Rig(spec, "LCP", LCP1, jacs_answer)
    rig.run(1.0)
    swing(rig, 1.0)
    rig.run(2.5)
    hx, hy = G.hip(1)
    feet = [(t, fk(G, 1, *q)) for t, q in commanded(rig) if 1.0 < t < 2.2]
    start = G.neutral_foot(1)
    early = [p for t, p in feet if t < 1.0 + T.LCP_SWING_EDGE - 0.1]
    late = [p for t, p in feet if t > 2.0 - T.LCP_SWING_EDGE + 0.1]
    assert early and late
    assert all(p[0] == pytest.approx(start[0], abs=1e-3) for p in early)                  # straight up first
    assert early[-1][2] > 0.01
    assert all(p[0] == pytest.approx(hx + 0.04, abs=1e-3) for p in late)                 # straight down last
    assert max(p[2] for _, p in feet) == pytest.approx(0.03, abs=5e-4)


def test_blocked_swing_retracts_retries_high_and_fails_when_blocked_again(spec):
    current = {"ma": 50}

    def respond(f):
        return answer(current_ma=current["ma"])(f)
    rig = Rig(spec, "LCP", LCP1, respond)
    rig.run(1.0)
    swing(rig, 1.0)
    rig.run(1.4)
    current["ma"] = 1800                                       # seed 6.1: the foot hits something, stall current
    rig.run(1.5)
    node = rig.node
    assert node.seg.swing and node.seg.lift == pytest.approx(G.step_limit + T.LCP_RETRY_CLEARANCE_M)
    back = node.seg.start
    assert back[0] < G.hip(1)[0] + 0.04                          # pulled back towards the lift-off point
    assert report(rig, 1.5).flags & LegFlags.BLOCKED
    assert status(rig, 1.55) == OrderStatus.IN_ORDER             # blocked once: it re-plans, not failed
    rig.run(1.9)                                                 # still stalled well into the retry
    assert node.failed and status(rig, 1.9) == OrderStatus.OUT_OF_ORDER     # leg drive failed
    current["ma"] = 50
    stance(rig, 2.1)
    swing(rig, 3.2, x=30)                                        # the next swing steps high, and cleanly
    rig.run(3.3)
    assert node.seg.lift == pytest.approx(G.step_limit + T.LCP_RETRY_CLEARANCE_M)
    stance(rig, 4.3)
    rig.run(4.4)
    assert not report(rig, 4.4).flags & LegFlags.BLOCKED         # a clean step clears the block
    assert status(rig, 4.5) == OrderStatus.IN_ORDER
    assert sum(1 for _, e, _ in rig.board.notes if e == "blocked") >= 2


def test_no_ground_under_a_stance_foot_hovers_and_clears_on_contact(spec):
    rig = Rig(spec, "LCP", LCP1, jacs_at_set_point())
    rig.run(1.0)
    stance(rig, 1.0, x=0, ms=3000)
    rig.run(1.0 + T.LCP_SETTLE_S - 0.1)
    rig.board.sole = False                                       # over a pit: the sole finds nothing
    rig.run(1.2 + T.LCP_SETTLE_S / 2)
    assert not report(rig, rig.board.t).flags & LegFlags.NO_GROUND     # not yet: contact lost just now
    rig.run(1.3 + T.LCP_SETTLE_S + 0.1)
    r = report(rig, rig.board.t)
    assert r.flags & LegFlags.NO_GROUND and not r.flags & LegFlags.CONTACT
    rig.run(rig.board.t + 0.3)
    _, q = commanded(rig)[-1]
    assert fk(G, 1, *q)[2] == pytest.approx(T.LCP_NO_GROUND_Z_M, abs=5e-4)   # no weight on it: it hovers
    assert any(e == "no_ground" for _, e, _ in rig.board.notes)
    rig.board.sole = True
    rig.run(rig.board.t + 0.2)
    assert not report(rig, rig.board.t).flags & LegFlags.NO_GROUND


def test_a_silent_jac_is_a_jac_fault(spec):
    rig = Rig(spec, "LCP", LCP1, jacs_answer)
    rig.run(1.0)
    rig.respond = answer(silent=(JACS[1],))
    rig.run(3.0)
    assert report(rig, 3.0).flags & LegFlags.JAC_FAULT
    assert status(rig, 3.1) == OrderStatus.OUT_OF_ORDER
    assert [d for _, e, d in rig.board.notes if e == "jac_fault"] == [{"leg": 1, "jac": JACS[1]}]
    n = len(rig.frames(M.JointTarget, JACS[1]))
    rig.run(4.0)
    assert len(rig.frames(M.JointTarget, JACS[1])) == n          # no more set points to it


def test_servo_overtemperature_is_reported_with_the_temperature(spec):
    rig = Rig(spec, "LCP", LCP1, answer(temp=75, flags=int(JointFlags.OVERTEMP)))
    rig.run(1.0)
    r = report(rig, 1.0)
    assert r.flags & LegFlags.OVERTEMP and r.servo_temp == 75
    assert sum(1 for _, e, _ in rig.board.notes if e == "servo_overtemp") == 1   # once, not per poll
    rig.respond = answer(temp=60)
    rig.run(2.0)
    assert not report(rig, 2.0).flags & LegFlags.OVERTEMP


STUCK = (G.hip(1)[0] + 0.01, G.hip(1)[1] + 0.11, 0.02)          # a foot caught 2 cm up on its way down


def _stuck_rig(spec, stalled) -> Rig:
    """LCP(1) whose JACs report the foot at STUCK; `stalled(poll number)` says whether a poll reads stall current.
    A HOLD target to x=40 mm, y=120 mm on the ground goes out at 1.0 s."""
    q = ik(G, 1, *STUCK)
    polls = {"n": 0}

    def respond(f):                                              # the servos report where the foot is
        if isinstance(f.message, M.JointPoll):
            polls["n"] += 1
            angle = _FB_DEG.raw(math.degrees(q[JACS.index(f.dst)]))
            current = 1800 if stalled(polls["n"]) else 50
            return [(f.dst, M.JointFeedback(angle=angle, speed=0, current=current, temperature=35, flags=0))]
        return jacs_answer(f)
    rig = Rig(spec, "LCP", LCP1, respond)
    rig.run(1.0)
    rig.inject(1.0, MMC, M.LegTarget.from_phys(phase=int(LegPhase.HOLD), x=40, y=120, z=0, duration=2000))
    return rig


def _held_where_it_stuck(rig: Rig) -> None:
    _, last = commanded(rig)[-1]
    # held where it stuck, not pushed on to x=40 mm, and set straight down from there (issue 17: a foot left
    # hanging on a wall's face found no ground and read as a pit)
    assert fk(G, 1, *last) == pytest.approx((STUCK[0], STUCK[1], 0.0), abs=2e-3)
    assert sum(1 for _, e, _ in rig.board.notes if e == "stall_hold") == 1
    assert rig.node.debug_metrics()["stall_holds"] == 1
    assert not rig.node.seg.swing and rig.node.seg.done(rig.board.t)


def test_a_foot_stalled_outside_a_swing_stops_where_it_is(spec):
    """seed 3.2.10 / 6.1, issue 18: a foot set down or held against a wall stalls outside a swing. The LCP
    used to keep pushing it there at stall current for good (the servos cooked, a full battery sagged under
    the PSC's alarm limit); now it stops the foot where the JACs report it and sets it straight down."""
    stalled = {"on": False}
    rig = _stuck_rig(spec, lambda n: stalled["on"])
    rig.run(1.3)
    stalled["on"] = True                                         # it runs into something: stall current
    rig.run(1.3 + T.LCP_STALL_HOLD_S / 2)
    assert rig.node.stall_holds == 0                             # a moment's stall: it pushes on (the set-down)
    rig.run(1.4 + T.LCP_STALL_HOLD_S + 3 * T.LCP_CONTROL_S)      # every JAC polled again after the hold time
    stalled["on"] = False                                        # stopped: the servos draw holding current
    rig.run(3.0)
    _held_where_it_stuck(rig)


def test_a_leg_stalling_and_slipping_by_turns_is_stopped_too(spec):
    """Issue 18, explore seed 4: a foot scraping along a wall stalls and slips by turns, so every other poll
    read a clean current. Each JAC's stall timer restarted at its clean reading and the leg pushed on at stall
    current; the stall is the leg's, over until a whole round of polls reads clean."""
    stalled = {"on": False}
    rig = _stuck_rig(spec, lambda n: stalled["on"] and n % 2 == 0)
    rig.run(1.3)
    stalled["on"] = True
    rig.run(1.3 + T.LCP_STALL_HOLD_S + 6 * T.LCP_CONTROL_S)
    stalled["on"] = False
    rig.run(3.0)
    _held_where_it_stuck(rig)


def test_a_foot_held_up_on_a_face_is_not_a_pit(spec):
    """Issue 17/18 (start_at_wall seeds 9-10, fault_us_killed_explore seed 16): a foot caught on a wall's face
    has no sole contact, but its JACs put it 2 cm up: something holds it, it is not over a pit."""
    rig = _stuck_rig(spec, lambda n: False)
    rig.board.sole = False
    rig.run(1.0 + 4 * T.LCP_SETTLE_S)
    r = report(rig, rig.board.t)
    assert not r.flags & LegFlags.NO_GROUND and not r.flags & LegFlags.CONTACT
    assert not any(e == "no_ground" for _, e, _ in rig.board.notes)
