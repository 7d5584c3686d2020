"""JAC(n,m) (seed 3.2.18): one servo's position loop, and its feedback to the LCP.

seed 3.2.18: the JAC drives one servo and measures the segment's position
(potentiometer) and the joint's angular speed (tacho generator). Its own
timer runs the control loop: a proportional controller on the potentiometer
angle whose speed command is limited to the speed the LCP's JOINT_TARGET
asks for. The tacho tells a stalled joint (commanded to turn, not turning,
seed 6.1) and AT_TARGET (there and at rest). JOINT_FEEDBACK reports angle,
speed, motor current, winding temperature and the flags; OVERTEMP has a
hysteresis so the flag does not chatter. A JAC that has heard no set point
for `JAC_WATCHDOG_S` (its LCP is gone) stops the servo's pulses: the leg goes
limp instead of standing stiff in the other legs' way (CHOICE).
"""
from __future__ import annotations

import math
from typing import TypedDict

from arachnae_proto import messages as M
from arachnae_proto.enums import JointFlags
from arachnae_proto.skeletons.jac import JacSkeleton

from behaviours import tuning as T
from behaviours.runtime import Runtime
from behaviours.units import quantizer

_TARGET_DEG = quantizer(M.JointTarget, "angle")
_TARGET_DEG_S = quantizer(M.JointTarget, "speed")
_FB_DEG = quantizer(M.JointFeedback, "angle")
_FB_DEG_S = quantizer(M.JointFeedback, "speed")
_FB_MA = quantizer(M.JointFeedback, "current")
_FB_TEMP = quantizer(M.JointFeedback, "temperature")
_OVERCURRENT, _STALLED = int(JointFlags.OVERCURRENT), int(JointFlags.STALLED)
_OVERTEMP, _AT_TARGET = int(JointFlags.OVERTEMP), int(JointFlags.AT_TARGET)


def drive_command(target: float, angle: float, limit: float) -> float:
    """seed 3.2.18: P control on the potentiometer angle, limited to the commanded speed (rad, rad/s)."""
    err = target - angle
    if abs(err) < T.JAC_DEADBAND_RAD:
        return 0.0
    return max(-limit, min(limit, T.JAC_KP * err))


class JacDebug(TypedDict):
    """JAC.debug_metrics(): metrics.json `nodes.<JAC>` (sim2d.metrics checks expectations on it at load)."""
    temperature_c: float
    flags: int


class JAC(Runtime, JacSkeleton):
    def start(self) -> None:
        self.target: float | None = None       # rad
        self.limit = 0.0                       # rad/s
        self.heard = 0.0                       # when the last set point came
        self.drive = 0.0
        self.stall_since: float | None = None
        self.stalled = False
        self.overtemp = False
        self.limp = False
        self.every(T.JAC_CONTROL_S, self.loop)

    def on_joint_target(self, src: int, msg: M.JointTarget) -> None:
        self.target = math.radians(_TARGET_DEG.phys(msg.angle))
        self.limit = math.radians(_TARGET_DEG_S.phys(msg.speed))
        self.heard = self.now
        self.limp = False

    def loop(self) -> None:
        """The servo's control loop, every JAC_CONTROL_S on the JAC's own timer."""
        s = self.hw.servo_state()
        # seed 3.2.18 / 3.2.15: winding temperature; the flag clears only JAC_OVERTEMP_HYST_C below the limit
        if s.temperature >= T.JAC_OVERTEMP_C:
            self.overtemp = True
        elif s.temperature < T.JAC_OVERTEMP_C - T.JAC_OVERTEMP_HYST_C:
            self.overtemp = False
        if self.target is None or self.limp:
            return
        if self.now - self.heard > T.JAC_WATCHDOG_S:
            self.limp = True                   # CHOICE: no set points from the LCP: no pulses
            self.hw.set_servo_drive(None)
            return
        self.drive = drive_command(self.target, s.angle, self.limit)
        self.hw.set_servo_drive(self.drive)
        # seed 6.1: commanded to turn but the tacho says it does not: stalled
        if abs(self.drive) >= T.JAC_STALL_MIN_DRIVE and abs(s.speed) < T.JAC_STALL_SPEED:
            if self.stall_since is None:
                self.stall_since = self.now
            self.stalled = self.now - self.stall_since >= T.JAC_STALL_S
        else:
            self.stall_since, self.stalled = None, False

    def flags(self) -> int:
        s = self.hw.servo_state()
        f = 0
        if s.current >= T.JAC_STALL_CURRENT_A:
            f |= _OVERCURRENT
        if self.stalled:
            f |= _STALLED
        if self.overtemp:
            f |= _OVERTEMP
        if (self.target is not None and abs(self.target - s.angle) < T.JAC_AT_TARGET_RAD
                and abs(s.speed) < T.JAC_STALL_SPEED):
            f |= _AT_TARGET
        return f

    def on_joint_poll(self, src: int, msg: M.JointPoll) -> None:
        s = self.hw.servo_state()
        self.send(src, M.JointFeedback(angle=_FB_DEG.raw(math.degrees(s.angle)), speed=_FB_DEG_S.raw(math.degrees(s.speed)),
                                       current=_FB_MA.raw(s.current * 1000), temperature=_FB_TEMP.raw(s.temperature),
                                       flags=self.flags()))

    def debug_metrics(self) -> JacDebug:
        """Debug port: the servo's winding temperature and flags at the end of a run."""
        s = self.hw.servo_state()
        return {"temperature_c": round(s.temperature, 1), "flags": self.flags()}
