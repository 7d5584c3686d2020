"""The pinned-body check (issue 17, seed 5.1.2): a body held by something no sensor sees (a thin post under the
sonar in the gap between the IR fan and the whiskers) while the legs walk on. The sonar's ranges at the scan
angles the SPU drives are cast in a 6 m x 4 m room from where the body really is, the dead reckoning walks on
at the NP3's speed: held, the check finds it within a few sweeps; walking, at any heading, never."""
from __future__ import annotations

import math

import pytest

from behaviours.np3_layers import BACKWARD, FORWARD, LEFT, RIGHT, PinnedCheck, Tuning, pinned_trigger
from behaviours.spu import SonarScan

TUNING = Tuning()
ROOM = (6.0, 4.0)
PING_S = 0.6           # one sonar reading per SPU poll round (measured in scenarios: 0.6 s)


def room_range(x: float, y: float, bearing: float) -> float:
    """Distance from (x, y) along `bearing` to the room's walls."""
    c, s = math.cos(bearing), math.sin(bearing)
    hits = [t for t in ((ROOM[0] - x) / c if c > 1e-9 else math.inf, -x / c if c < -1e-9 else math.inf,
                        (ROOM[1] - y) / s if s > 1e-9 else math.inf, -y / s if s < -1e-9 else math.inf) if t > 0]
    return min(hits)


def walk(start: tuple[float, float, float], held: bool, seconds: float) -> float | None:
    """Walk FORWARD from `start` for `seconds`; the body stays at the start if `held`. When the check says pinned."""
    check, scan = PinnedCheck(TUNING), SonarScan()
    check.command(0.0, FORWARD)
    x0, y0, th = start
    t = 0.0
    while t < seconds:
        t += PING_S
        dr = (x0 + TUNING.walk_speed_m_s * t * math.cos(th), y0 + TUNING.walk_speed_m_s * t * math.sin(th))
        real = (x0, y0) if held else dr
        angle = scan.next()
        rel = (angle + 180) % 360 - 180
        d = room_range(*real, th + math.radians(rel)) + (0.01 if int(t / PING_S) % 2 else -0.01)   # sonar noise
        scan.heard(angle, d)
        if check.heard(rel, d, t, dr, alongside=False):
            return t
    return None


@pytest.mark.parametrize("heading_deg", [0.0, -18.0, 45.0, 90.0, 180.0])
def test_a_held_body_is_found_within_a_few_sweeps(heading_deg):
    found = walk((2.0, 2.0, math.radians(heading_deg)), held=True, seconds=20.0)
    assert found is not None and found <= 10.0, found


@pytest.mark.parametrize("heading_deg", [0.0, -18.0, 45.0, 90.0, 180.0])
def test_a_walking_body_is_never_taken_for_held(heading_deg):
    assert walk((2.0, 2.0, math.radians(heading_deg)), held=False, seconds=14.0) is None


def test_a_wall_alongside_says_nothing():
    check = PinnedCheck(TUNING)
    check.command(0.0, FORWARD)
    for k in range(40):       # the same range at every angle while the reckoning walks on
        assert not check.heard((-15, 0, 15)[k % 3], 2.0, 0.6 * k, (0.054 * k, 0.0), alongside=True)
    assert check.alongside([(0.0, 0.3, 90.0, 0.0)]) and not check.alongside([(1.5, 0.0, 0.0, 0.0)])


def test_a_step_back_restarts_the_check_and_a_turn_does_not():
    check = PinnedCheck(TUNING)
    check.command(0.0, FORWARD)
    check.command(1.0, LEFT)
    assert check.since == 0.0
    check.command(2.0, BACKWARD)
    assert check.since is None
    assert not check.heard(0, 2.0, 3.0, (0.0, 0.0), alongside=False)


def test_pinned_backs_off_then_turns_the_front_away():
    trigger = pinned_trigger(TUNING)
    assert trigger({"pinned": 0}, 0.0) is None
    steps = trigger({"pinned": 1, "pose": (0.0, 0.0, 0.0), "echoes": ()}, 1.0)
    assert steps is not None and steps[0][1] == BACKWARD and steps[-1][1] in (LEFT, RIGHT)
    turned = steps[-1][0] * TUNING.turn_rate_deg_s
    assert turned >= 90.0                         # the front (where it was held) ends behind the side
