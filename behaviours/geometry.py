"""The robot's mechanical dimensions as the MMC and LCP firmware know them.

Gait planning (MMC) and inverse kinematics (LCP) need the leg geometry and
the gait's stroke; the simulator's physics (sim2d.robot_params) extends this
class, so firmware and simulated body share one set of numbers. Units:
metres, seconds, radians. CHOICE marks values the seed does not give
(its figures Abb. 1-4 are missing).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import NamedTuple


class BodyPoint(NamedTuple):
    """A point in the body frame (m): x forward from the body's centre, y to its left."""
    x: float
    y: float


FeelerArm = tuple[BodyPoint, ...]   # a rigid wire from its root, point to point (seed 1.2.2 "Fühler")


def mirrored(arms: tuple[FeelerArm, ...]) -> tuple[FeelerArm, ...]:
    """The right feeler's arms from the left one's: the body is symmetric about its axis."""
    return tuple(tuple(BodyPoint(p.x, -p.y) for p in arm) for arm in arms)


def along(arm: FeelerArm, share: float) -> BodyPoint:
    """The point `share` (0 root .. 1 tip) of the way along a wire: a touch is somewhere on it, the switch does
    not say where."""
    left = share * sum(math.dist(a, b) for a, b in zip(arm, arm[1:]))
    for a, b in zip(arm, arm[1:]):
        n = math.dist(a, b)
        if 0 < n and left <= n:
            return BodyPoint(a.x + left / n * (b.x - a.x), a.y + left / n * (b.y - a.y))
        left -= n
    return arm[-1]


@dataclass(frozen=True)
class RobotGeometry:
    body_width: float = 0.16              # CHOICE
    body_height: float = 0.12             # CHOICE: top of body above ground when standing
    hip_height: float = 0.09              # CHOICE: hip joints above ground
    hip_x: tuple[float, ...] = (0.12, 0.0, -0.12)   # CHOICE: front, middle, rear hips (body frame)
    femur: float = 0.08                   # CHOICE: segment moved by servo 1
    tibia: float = 0.12                   # CHOICE: segment moved by servo 3
    neutral_reach: float = 0.12           # CHOICE: horizontal hip-to-foot distance at rest
    stroke: float = 0.08                  # seed 1.1: ARACHNAE I "maximaler Vorschub von 8 cm"
    lift: float = 0.03                    # seed 1.1: ARACHNAE I "maximaler Hub von 3 cm"
    speed: float = 0.10                   # seed 1.1: tripod gait "etwa 10 cm/sec"
    turn_stroke_rad: float = math.radians(20)  # CHOICE: body rotation per tripod half cycle
    legs: tuple[int, ...] = field(default=(1, 2, 3, 4, 5, 6))

    @property
    def step_limit(self) -> float:
        """Highest obstacle a foot can step over: half the body height (seed 1.2.1)."""
        return self.body_height / 2

    @property
    def half_cycle(self) -> float:
        """Seconds per tripod half cycle so that one stroke per half cycle gives `speed`."""
        return self.stroke / self.speed

    def hip(self, leg: int) -> tuple[float, float]:
        """Hip position of leg 1..6 in the body frame (x forward, y left).

        CHOICE: legs 1-3 on the left, front to rear; 4-6 on the right, front to rear.
        """
        side = 1.0 if leg <= 3 else -1.0
        return (self.hip_x[(leg - 1) % 3], side * self.body_width / 2)

    def side(self, leg: int) -> float:
        return 1.0 if leg <= 3 else -1.0

    def neutral_foot(self, leg: int) -> tuple[float, float]:
        hx, hy = self.hip(leg)
        return (hx, hy + self.side(leg) * self.neutral_reach)

    def tripod_group(self, leg: int) -> int:
        """Legs 1,3,5 form tripod 0 and 2,4,6 tripod 1 (each a stable triangle)."""
        return 0 if leg in (1, 3, 5) else 1


DEFAULT_GEOMETRY = RobotGeometry()
