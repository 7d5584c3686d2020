"""JAC(n,m) (seed 3.2.18): drives one servo; reports position, speed, current, temperature."""
from __future__ import annotations

import math

from sim2d.behaviours.base import NodeProcess


class JAC(NodeProcess):
    def start(self) -> None:
        self.leg, self.joint = self.node.leg, self.node.joint

    def on_joint_target(self, bus: str, src: int, f: dict) -> None:
        self.ctx.robot.set_joint_target(self.leg, self.joint, math.radians(f["angle"] / 10), math.radians(f["speed"] / 10))

    def on_joint_poll(self, bus: str, src: int, f: dict) -> None:
        angle, speed, current = self.ctx.sensors.joint(self.leg, self.joint)
        bits = self.ctx.spec.flags["JOINT_FLAGS"].bits
        j = self.ctx.robot.legs[self.leg].joints[self.joint - 1]
        flags = 0
        if current >= self.ctx.params.servo_stall_a:
            flags |= bits["STALLED"] | bits["OVERCURRENT"]
        if abs(j.target - j.angle) < 1e-3:
            flags |= bits["AT_TARGET"]
        self.reply(bus, src, "JOINT_FEEDBACK", angle=max(-1800, min(1800, round(math.degrees(angle) * 10))),
                   speed=max(-6000, min(6000, round(math.degrees(speed) * 10))), current=min(5000, round(current * 1000)),
                   temperature=round(self.ctx.scenario.ambient_temp), flags=flags)

    def kill(self) -> None:
        super().kill()
        # a dead JAC sends no more pulses: the hobby servo goes limp (CHOICE)
        self.ctx.robot.legs[self.leg].joints[self.joint - 1].powered = False
