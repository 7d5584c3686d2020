"""LCP(n) (seed 3.2.10): one leg's trajectory, its three servos, and its local reflexes.

From a LEG_TARGET it interpolates the foot from where it is to the target:
a straight line in stance, an arc lifted by z in swing. Every control period
the foot point goes through the inverse kinematics (behaviours.kinematics)
to JOINT_TARGETs; an unchanged set point is repeated every
`setpoint_refresh_ms` (spec protocol). While swinging it polls its JACs; a
motor current above the limit means the leg is blocked (seed 6.1): the LCP
retracts the foot, lifts it as high as the step limit allows and tries
again. The sole switch is read locally (3.2.10).
"""
from __future__ import annotations

import math

from arachnae_proto import messages as M
from arachnae_proto.enums import LegFlags, LegPhase
from arachnae_proto.skeletons.lcp import LcpSkeleton

from behaviours import tuning as T
from behaviours.kinematics import ik
from behaviours.post import PostMaster
from behaviours.runtime import Runtime, slaves_of
from behaviours.units import quantizer

_MM = quantizer(M.LegTarget, "x")
_DEG = quantizer(M.JointTarget, "angle")
_DEG_S = quantizer(M.JointTarget, "speed")
_TEMP = quantizer(M.LegReport, "servo_temp")
_CONTACT, _BLOCKED = int(LegFlags.CONTACT), int(LegFlags.BLOCKED)
_NO_GROUND, _SWINGING = int(LegFlags.NO_GROUND), int(LegFlags.SWINGING)
_STANCE = int(LegPhase.STANCE)
_DEG_PER_RAW = _DEG.phys(1)                  # JOINT_TARGET angle resolution
_TOP_SPEED = _DEG_S.phys(_DEG_S.hi)         # the speed field's maximum


class LCP(PostMaster, Runtime, LcpSkeleton):
    def start(self) -> None:
        g = self.cfg.geometry
        self.leg = self.net.leg_of(self.address)
        self.jacs = sorted(slaves_of(self.master_bus), key=lambda a: self.net.joint_of(a))
        nx, ny = g.neutral_foot(self.leg)
        self.pos = (nx, ny, 0.0)
        self.target: tuple | None = None      # (phase, x, y, z) raw of the LEG_TARGET being executed
        self.seg = None                       # (start, end, lift, t0, duration)
        self.phase = -1
        self.flags = 0
        self.retried = False
        self.poll_i = 0
        self.sent_angles: dict[int, int] = {}
        self.sent_at: dict[int, float] = {}
        self.servo_temp: dict[int, float] = {}
        self.run_post(self.post_done)
        self.every(T.LCP_CONTROL_S, self.tick)

    def post_done(self, missing: list[int]) -> None:
        for a in self.jacs:                   # one feedback each: the servo temperatures for LEG_REPORT
            if a not in missing:
                self.request(a, M.JointPoll(), (M.JointFeedback,), self.feedback)

    def live_jacs(self) -> list[int]:
        return [a for a in self.jacs if a not in (self.post_missing or ())]

    def on_leg_target(self, src: int, msg: M.LegTarget) -> None:
        key = (msg.phase, msg.x, msg.y, msg.z)
        if key == self.target and self.seg is not None:
            return                            # a refresh of the target being executed (spec setpoint_refresh_ms)
        g = self.cfg.geometry
        hx, hy = g.hip(self.leg)
        end = (_MM.phys(msg.x) / 1000 + hx, _MM.phys(msg.y) / 1000 + hy, 0.0)
        self.target = key
        self.phase = msg.phase
        self.seg = (self.pos, end, _MM.phys(msg.z) / 1000, self.now, msg.duration / 1000)
        self.retried = False
        self.flags &= ~_BLOCKED

    def foot_at(self, t: float) -> tuple[float, float, float]:
        if self.seg is None:
            return self.pos
        start, end, lift, t0, dur = self.seg
        s = 1.0 if dur <= 0 else min(1.0, max(0.0, (t - t0) / dur))
        z = lift * math.sin(math.pi * s) if lift > 0 else 0.0
        return (start[0] + (end[0] - start[0]) * s, start[1] + (end[1] - start[1]) * s, z)

    def tick(self) -> None:
        if self.post_missing is None:
            return
        t = self.now
        period = T.LCP_CONTROL_S
        self.pos = self.foot_at(t + period)
        contact = self.hw.sole_contact()
        self.flags = (self.flags | _CONTACT) if contact else (self.flags & ~_CONTACT)
        swinging = self.seg is not None and self.seg[2] > 0 and t < self.seg[3] + self.seg[4]
        self.flags = (self.flags | _SWINGING) if swinging else (self.flags & ~_SWINGING)
        if contact:
            self.flags &= ~_NO_GROUND
        elif self.seg is not None and self.phase == _STANCE and t - self.seg[3] > T.LCP_SETTLE_S:
            self.flags |= _NO_GROUND          # seed 1.2.2: the sole finds no ground (a pit)
        q = ik(self.cfg.geometry, self.leg, *self.pos)
        refresh = self.net.protocol.setpoint_refresh_s
        live = self.live_jacs()
        for a in live:
            joint = self.net.joint_of(a)
            raw = _DEG.raw(math.degrees(q[joint - 1]))
            last = self.sent_angles.get(joint)
            if last == raw and t - self.sent_at.get(joint, 0.0) < refresh - 1e-9:
                continue
            self.sent_angles[joint] = raw
            self.sent_at[joint] = t
            # a margin over the speed that arrives in one period, with a floor: a joint catches up
            # after a lost set point; the first set point goes at full speed
            needed = _TOP_SPEED if last is None else T.LCP_SPEED_MARGIN * abs(raw - last) * _DEG_PER_RAW / period
            speed = _DEG_S.raw(max(T.LCP_MIN_SPEED_DEG_S, needed))
            self.request(a, M.JointTarget(angle=raw, speed=speed))
        if swinging and live:
            a = live[self.poll_i % len(live)]
            self.poll_i += 1
            self.request(a, M.JointPoll(), (M.JointFeedback,), self.feedback)

    def feedback(self, src: int, fb: M.JointFeedback) -> None:
        self.servo_temp[src] = fb.temperature
        if fb.current < T.LCP_BLOCK_CURRENT_A * 1000 or self.seg is None:
            return
        self.flags |= _BLOCKED
        self.hw.note("blocked", leg=self.leg)
        if self.retried:
            return
        # seed 6.1: retract the leg and compute a new trajectory, lifted to the step limit
        self.retried = True
        g = self.cfg.geometry
        start, end, lift, t0, dur = self.seg
        left = max(T.LCP_RETRY_MIN_S, t0 + dur - self.now)
        r = T.LCP_RETRACT
        back = (self.pos[0] + r * (start[0] - self.pos[0]), self.pos[1] + r * (start[1] - self.pos[1]), 0.0)
        self.seg = (back, end, g.step_limit + T.LCP_RETRY_CLEARANCE_M, self.now, left)

    def on_leg_poll(self, src: int, msg: M.LegPoll) -> None:
        g = self.cfg.geometry
        hx, hy = g.hip(self.leg)
        x, y, z = self.pos
        temp = max(self.servo_temp.values()) if self.servo_temp else 0.0
        self.send(src, M.LegReport(flags=self.flags, x=_MM.raw((x - hx) * 1000), y=_MM.raw((y - hy) * 1000),
                                   z=_MM.raw(z * 1000), servo_temp=_TEMP.raw(temp)))
