"""JAC(n,m) (seed 3.2.18): drives one servo; reports position, speed, current, temperature."""
from __future__ import annotations

import math

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
_STALL = int(JointFlags.STALLED | JointFlags.OVERCURRENT)
_AT_TARGET = int(JointFlags.AT_TARGET)


class JAC(Runtime, JacSkeleton):
    def start(self) -> None:
        self.target: float | None = None       # rad

    def on_joint_target(self, src: int, msg: M.JointTarget) -> None:
        self.target = math.radians(_TARGET_DEG.phys(msg.angle))
        self.hw.set_servo(self.target, math.radians(_TARGET_DEG_S.phys(msg.speed)))

    def on_joint_poll(self, src: int, msg: M.JointPoll) -> None:
        s = self.hw.servo_state()
        flags = 0
        if s.current >= T.JAC_STALL_CURRENT_A:
            flags |= _STALL
        if self.target is not None and abs(self.target - s.angle) < T.JAC_AT_TARGET_RAD:
            flags |= _AT_TARGET
        self.send(src, M.JointFeedback(angle=_FB_DEG.raw(math.degrees(s.angle)), speed=_FB_DEG_S.raw(math.degrees(s.speed)),
                                       current=_FB_MA.raw(s.current * 1000), temperature=_FB_TEMP.raw(s.temperature),
                                       flags=flags))
