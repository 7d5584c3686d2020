"""LCP (seed 3.2.10): inverse kinematics of the 3-joint leg, and the LCP putting the foot where asked."""
from __future__ import annotations

import math

import pytest
from hypothesis import given, settings, strategies as st

from arachnae_proto import messages as M
from arachnae_proto.enums import LegFlags, LegPhase

from behaviours import tuning as T
from behaviours.geometry import DEFAULT_GEOMETRY as G
from behaviours.kinematics import fk, ik
from tests.behaviours.rig import Rig

L1, L2, H = G.femur, G.tibia, G.hip_height
MMC, LCP1 = 0x03, 0x21
JACS = (0x41, 0x42, 0x43)                      # JAC(1,1..3), seed 3.2.18


def foot(leg: int, reach: float, swing: float, z: float) -> tuple[float, float, float]:
    """Body-frame foot point `reach` out from the hip, leg swung `swing` rad forward, height z."""
    hx, hy = G.hip(leg)
    return (hx + reach * math.sin(swing), hy + G.side(leg) * reach * math.cos(swing), z)


# closed-form golden cases (hand-derived): (foot point, joint angles q1 femur lift, q2 swing, q3 knee)
GOLDEN = [
    # leg stretched straight out at hip height: every joint at zero
    (foot(1, L1 + L2, 0.0, H), (0.0, 0.0, 0.0)),
    # femur level, tibia straight down: knee bent 90 degrees, foot L1 out and L2 below the hip
    (foot(1, L1, 0.0, H - L2), (0.0, 0.0, math.pi / 2)),
    # the same, leg swung 30 degrees forward; on the right side the swing mirrors in y only
    (foot(1, L1, math.radians(30), H - L2), (0.0, math.radians(30), math.pi / 2)),
    (foot(5, L1, math.radians(-20), H - L2), (0.0, math.radians(-20), math.pi / 2)),
    # femur raised 45 degrees, tibia straight down: knee at 135 degrees
    (foot(2, L1 / math.sqrt(2), 0.0, H + L1 / math.sqrt(2) - L2), (math.pi / 4, 0.0, 3 * math.pi / 4)),
]


@pytest.mark.parametrize("leg, case", [(1, 0), (1, 1), (1, 2), (5, 3), (2, 4)])
def test_ik_golden_cases(leg, case):
    target, angles = GOLDEN[case]
    assert ik(G, leg, *target) == pytest.approx(angles, abs=1e-9)
    assert fk(G, leg, *angles) == pytest.approx(target, abs=1e-12)


@settings(max_examples=200, deadline=None)
@given(leg=st.integers(1, 6), dx=st.floats(-0.05, 0.05), dy=st.floats(-0.03, 0.03), z=st.floats(0.0, 0.06))
def test_ik_inverts_fk_in_the_workspace(leg, dx, dy, z):
    nx, ny = G.neutral_foot(leg)
    target = (nx + dx, ny + dy, z)
    assert fk(G, leg, *ik(G, leg, *target)) == pytest.approx(target, abs=1e-9)


def jacs_answer(f):
    m = f.message
    if isinstance(m, M.IdReq):
        return [(f.dst, M.IdAck(address=f.dst))]
    if isinstance(m, M.StatusReq):
        return [(f.dst, M.StatusAckOrder(status=0))]
    if isinstance(m, M.JointPoll):
        return [(f.dst, M.JointFeedback(angle=0, speed=0, current=50, temperature=31, flags=0))]
    return []


def jacs_at_set_point():
    """JACs whose servos stand where they were last sent (the LCP reads the foot's height from them)."""
    sent: dict[int, int] = {}

    def respond(f):
        m = f.message
        if isinstance(m, M.JointTarget):
            sent[f.dst] = m.angle
        if isinstance(m, M.JointPoll):
            return [(f.dst, M.JointFeedback(angle=sent.get(f.dst, 0), speed=0, current=50, temperature=31, flags=0))]
        return jacs_answer(f)
    return respond


def commanded(rig: Rig) -> list[tuple[float, tuple[float, float, float]]]:
    """The joint angles (rad) the LCP has commanded, one complete set per control period, from the bytes it sent."""
    q = [None, None, None]
    out: dict[int, tuple[float, tuple]] = {}
    for t, f in rig.frames(M.JointTarget):
        q[JACS.index(f.dst)] = math.radians(f.message.phys()["angle"])
        if None not in q:
            out[round(t / T.LCP_CONTROL_S)] = (t, tuple(q))     # the set points of one period go out together
    return list(out.values())


@pytest.mark.parametrize("x_mm, y_mm", [(0.0, 120.0), (30.0, 110.0), (-35.0, 95.0)])
def test_lcp_puts_the_foot_where_the_leg_target_says(spec, x_mm, y_mm):
    rig = Rig(spec, "LCP", LCP1, jacs_answer)
    rig.inject(0.3, MMC, M.LegTarget.from_phys(phase=int(LegPhase.STANCE), x=x_mm, y=y_mm, z=0, duration=0))
    rig.run(1.0)
    _, q = commanded(rig)[-1]
    hx, hy = G.hip(1)
    # within the wire's 0.1 degree angle resolution: well under a millimetre
    assert fk(G, 1, *q) == pytest.approx((hx + x_mm / 1000, hy + y_mm / 1000, 0.0), abs=5e-4)


def test_lcp_swing_lifts_the_foot_by_z_at_mid_swing(spec):
    rig = Rig(spec, "LCP", LCP1, jacs_answer)
    rig.inject(0.3, MMC, M.LegTarget.from_phys(phase=int(LegPhase.SWING), x=40, y=120, z=30, duration=1000))
    rig.run(1.5)
    heights = [fk(G, 1, *q)[2] for t, q in commanded(rig)]
    assert 0.98 * 0.030 <= max(heights) <= 0.0305
    assert heights[-1] == pytest.approx(0.0, abs=5e-4)            # and sets it down at the end


def test_lcp_reports_blocked_leg_and_retries_higher(spec):
    def blocked(f):
        if isinstance(f.message, M.JointPoll):                   # seed 6.1: stall current in every joint
            return [(f.dst, M.JointFeedback(angle=0, speed=0, current=1800, temperature=35, flags=0))]
        return jacs_answer(f)
    rig = Rig(spec, "LCP", LCP1, blocked)
    rig.inject(0.3, MMC, M.LegTarget.from_phys(phase=int(LegPhase.SWING), x=40, y=120, z=30, duration=1000))
    rig.inject(0.8, MMC, M.LegPoll())
    rig.run(0.45)
    assert rig.node.seg.swing and rig.node.seg.lift == pytest.approx(G.step_limit + 0.01)  # retried, to the step limit
    rig.run(1.0)
    (_, f), = rig.frames(M.LegReport)
    assert f.message.flags & LegFlags.BLOCKED and f.message.servo_temp == 35
    assert rig.node.failed                                        # stalled through the retry too: drive failed
    assert any(e == "blocked" for _, e, _ in rig.board.notes)
