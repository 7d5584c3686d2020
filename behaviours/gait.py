"""The MMC's gait generator (seed 3.2.3/3.2.4): foot targets in the body frame.

A gait is a duty factor plus a phase offset per leg (tripod, ripple, wave:
seed 3.2.3 Mov_Cmd 7..9). Each leg alternates stance (foot on the ground,
moving against the body's motion) and swing (foot lifted, moving forward).
A new command takes effect at a leg's next stance/swing boundary, so a
foot never jumps while it carries the body.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from arachnae_proto.enums import MovCmd

from behaviours.geometry import RobotGeometry

# Mov_Cmd values of seed 3.2.3, as plain ints (the generated enum is the source; ints are faster).
STOP, FORWARD, BACKWARD = int(MovCmd.STOP), int(MovCmd.FORWARD), int(MovCmd.BACKWARD)
TURN_RIGHT, TURN_LEFT = int(MovCmd.TURN_RIGHT), int(MovCmd.TURN_LEFT)
SIDESTEP_RIGHT, SIDESTEP_LEFT = int(MovCmd.SIDESTEP_RIGHT), int(MovCmd.SIDESTEP_LEFT)
TRIPOD, RIPPLE, WAVE = int(MovCmd.TRIPOD), int(MovCmd.RIPPLE), int(MovCmd.WAVE)

# (vx, vy, w) per direction: body-frame unit motion, x forward, y left, w counter-clockwise.
MOTION = {
    STOP: (0.0, 0.0, 0.0), FORWARD: (1.0, 0.0, 0.0), BACKWARD: (-1.0, 0.0, 0.0),
    TURN_RIGHT: (0.0, 0.0, -1.0), TURN_LEFT: (0.0, 0.0, 1.0),
    SIDESTEP_RIGHT: (0.0, -1.0, 0.0), SIDESTEP_LEFT: (0.0, 1.0, 0.0),
}


def _offsets(gait: int) -> tuple[float, dict[int, float]]:
    """Duty factor and per-leg phase offsets. CHOICE: wave/ripple orders follow the usual hexapod patterns."""
    if gait == TRIPOD:
        return 0.5, {1: 0.0, 3: 0.0, 5: 0.0, 2: 0.5, 4: 0.5, 6: 0.5}
    if gait == RIPPLE:
        return 2 / 3, {1: 0.0, 5: 1 / 6, 3: 1 / 3, 4: 1 / 2, 2: 2 / 3, 6: 5 / 6}
    return 5 / 6, {1: 0.0, 2: 1 / 6, 3: 2 / 6, 4: 3 / 6, 5: 4 / 6, 6: 5 / 6}


@dataclass
class LegPlan:
    swing: bool = False
    start: tuple[float, float] = (0.0, 0.0)
    end: tuple[float, float] = (0.0, 0.0)
    lift: float = 0.0
    active: bool = True      # False: the leg stays put in stance (STOP reached neutral)
    s0: float = 0.0          # segment progress when the plan was last changed


class Gait:
    """The MMC's gait generator: advance(dt), then target(leg) gives (x, y, z) in the body frame."""

    def __init__(self, p: RobotGeometry, legs: tuple[int, ...] | None = None):
        self.p = p
        self.legs = legs or p.legs
        self.command = STOP
        self.gait = TRIPOD
        self.phase = 0.0
        self.lift_boost: dict[int, float] = {}
        self.plans = {leg: LegPlan(start=p.neutral_foot(leg), end=p.neutral_foot(leg), active=False) for leg in self.legs}
        self._set_gait(TRIPOD)

    def _set_gait(self, gait: int) -> None:
        self.gait = gait
        self.duty, self.offset = _offsets(gait)
        self.cycle = self.p.half_cycle / (1 - self.duty)   # every swing lasts one tripod half cycle

    def set_command(self, cmd: int) -> None:
        """Apply a Mov_Cmd: 0..6 set the direction, 7..9 the gait (seed 3.2.3)."""
        if cmd in (TRIPOD, RIPPLE, WAVE):
            self._set_gait(cmd)
        elif cmd in MOTION and cmd != self.command:
            self.command = cmd
            # react now (seed 5.2), not at the next step: every moving leg re-aims its current segment
            for leg in self.legs:
                pl = self.plans[leg]
                if pl.active:
                    x, y, _ = self.target(leg)
                    pl.start, pl.end, pl.s0 = (x, y), self._foot_end(leg, pl.swing), self._local(leg)[1]

    def _foot_end(self, leg: int, swing: bool) -> tuple[float, float]:
        vx, vy, w = MOTION[self.command]
        nx, ny = self.p.neutral_foot(leg)
        sign = 0.5 if swing else -0.5        # swing ends ahead, stance ends behind
        stroke = self.p.stroke
        a = sign * self.p.turn_stroke_rad * w
        c, s = math.cos(a), math.sin(a)
        return (c * nx - s * ny + sign * stroke * vx, s * nx + c * ny + sign * stroke * vy)

    def _local(self, leg: int) -> tuple[bool, float]:
        u = (self.phase - self.offset[leg]) % 1.0
        if u < self.duty:
            return False, u / self.duty
        return True, (u - self.duty) / (1 - self.duty)

    def advance(self, dt: float) -> None:
        moving = self.command != STOP or any(pl.active for pl in self.plans.values())
        if not moving:
            return
        if self.command != STOP and not any(pl.active for pl in self.plans.values()):
            self.phase = 0.0      # start from a clean tripod boundary, not mid-stride
        self.phase = (self.phase + dt / self.cycle) % 1.0
        for leg in self.legs:
            swing, _ = self._local(leg)
            pl = self.plans[leg]
            if swing != pl.swing or not pl.active:
                if not pl.active and self.command == STOP:
                    continue
                cur = self.target(leg)[:2]
                pl.swing = swing
                pl.start = cur
                pl.end = self._foot_end(leg, swing)
                pl.lift = self.p.lift + self.lift_boost.pop(leg, 0.0)
                pl.s0 = 0.0
                at_home = math.dist(cur, pl.end) < 1e-3
                pl.active = not (self.command == STOP and at_home)

    def boost_lift(self, leg: int, extra: float) -> None:
        """LCP reflex (seed 6.1): the next swing of `leg` lifts `extra` metres higher."""
        self.lift_boost[leg] = extra
        pl = self.plans[leg]
        if pl.swing:
            pl.lift = max(pl.lift, self.p.lift + extra)

    def target(self, leg: int) -> tuple[float, float, float]:
        pl = self.plans[leg]
        if not pl.active:
            return (pl.end[0], pl.end[1], 0.0)
        _, s = self._local(leg)
        u = 1.0 if pl.s0 >= 1.0 else max(0.0, (s - pl.s0) / (1.0 - pl.s0))
        x = pl.start[0] + (pl.end[0] - pl.start[0]) * u
        y = pl.start[1] + (pl.end[1] - pl.start[1]) * u
        z = pl.lift * math.sin(math.pi * s) if pl.swing else 0.0
        return (x, y, z)

    def in_swing(self, leg: int) -> bool:
        return self.plans[leg].active and self.plans[leg].swing
