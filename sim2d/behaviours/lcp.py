"""LCP(n) (seed 3.2.10): one leg's trajectory, its three servos, and its local reflexes.

From a LEG_TARGET it interpolates the foot from where it is to the target:
a straight line in stance, an arc lifted by z in swing. Every control period
the foot point goes through the inverse kinematics to JOINT_TARGETs. While
swinging it polls its JACs; a motor current above the limit means the leg is
blocked (seed 6.1): the LCP retracts the foot, lifts it as high as the
step limit allows and tries again. The sole switch is read locally (3.2.10).
"""
from __future__ import annotations

import math

from sim2d.behaviours.base import Master, Request
from sim2d.kinematics import ik

CONTROL_PERIOD = 0.1           # CHOICE: 10 Hz set points per joint, each with the speed to arrive in one period
BLOCK_CURRENT_MA = 1000        # CHOICE: above free-running current (350 mA), below stall (1.8 A)
SETTLE_S = 0.6                 # CHOICE: a stance foot without ground contact this long after touchdown -> no ground
REFRESH_S = 0.2                # CHOICE: an unchanged set-point is repeated, so a lost JOINT_TARGET costs at most this
MIN_SPEED = 300                # CHOICE: 30 deg/s floor (deci-degrees per second on the wire)
DEG10 = 10.0                   # JOINT_TARGET angle raw = deci-degrees (spec scale 1/10)


class LCP(Master):
    tick_period = CONTROL_PERIOD

    def start(self) -> None:
        p = self.ctx.params
        self.leg = self.node.leg
        self.jacs = sorted((n for n in self.ctx.spec.role_nodes("JAC") if n.leg == self.leg), key=lambda n: n.joint)
        nx, ny = p.neutral_foot(self.leg)
        self.pos = (nx, ny, 0.0)
        self.seg = None            # (start, end, lift, t0, duration)
        self.phase = -1
        self.flags = 0
        self.retried = False
        self.poll_i = 0
        self.sent_angles: dict[int, int] = {}
        self.sent_at: dict[int, float] = {}
        self.run_post()

    def on_leg_target(self, bus: str, src: int, f: dict) -> None:
        p = self.ctx.params
        hx, hy = p.hip(self.leg)
        end = (f["x"] / 10000 + hx, f["y"] / 10000 + hy, 0.0)
        self.phase = f["phase"]
        self.seg = (self.pos, end, f["z"] / 10000, self.now, f["duration"] / 1000)
        self.retried = False
        bits = self.ctx.spec.flags["LEG_FLAGS"].bits
        self.flags &= ~bits["BLOCKED"]

    def foot_at(self, t: float) -> tuple[float, float, float]:
        if self.seg is None:
            return self.pos
        start, end, lift, t0, dur = self.seg
        s = 1.0 if dur <= 0 else min(1.0, max(0.0, (t - t0) / dur))
        z = lift * math.sin(math.pi * s) if lift > 0 else 0.0
        return (start[0] + (end[0] - start[0]) * s, start[1] + (end[1] - start[1]) * s, z)

    def tick(self, t: float) -> None:
        if self.post_missing is None:
            return
        p = self.ctx.params
        bits = self.ctx.spec.flags["LEG_FLAGS"].bits
        self.pos = self.foot_at(t + CONTROL_PERIOD)
        contact = self.ctx.sensors.foot_contact(self.leg)
        self.flags = (self.flags | bits["CONTACT"]) if contact else (self.flags & ~bits["CONTACT"])
        swinging = self.seg is not None and self.seg[2] > 0 and t < self.seg[3] + self.seg[4]
        self.flags = (self.flags | bits["SWINGING"]) if swinging else (self.flags & ~bits["SWINGING"])
        if contact:
            self.flags &= ~bits["NO_GROUND"]
        elif self.seg is not None and self.phase == self.ctx.spec.enums["LEG_PHASE"].values["STANCE"] \
                and t - self.seg[3] > SETTLE_S:
            self.flags |= bits["NO_GROUND"]        # seed 1.2.2: the sole finds no ground (a pit)
        q = ik(p, self.leg, *self.pos)
        for jac in self.jacs:
            if jac.address in self.post_missing:
                continue
            raw = round(math.degrees(q[jac.joint - 1]) * DEG10)
            last = self.sent_angles.get(jac.joint)
            if last == raw and t - self.sent_at.get(jac.joint, 0.0) < REFRESH_S:
                continue
            self.sent_angles[jac.joint] = raw
            self.sent_at[jac.joint] = t
            # twice the nominal speed and a floor of MIN_SPEED: a joint catches up after a lost set-point;
            # at most the speed field's range (600 deg/s)
            nominal = 6000 if last is None else abs(raw - last) / CONTROL_PERIOD
            speed = min(6000, max(MIN_SPEED, round(2 * nominal)))
            self.request(self.node.masters, Request(jac.address, "JOINT_TARGET", {"angle": raw, "speed": speed}))
        if swinging:
            live = [j for j in self.jacs if j.address not in self.post_missing]
            if live:
                jac = live[self.poll_i % len(live)]
                self.poll_i += 1
                self.request(self.node.masters, Request(jac.address, "JOINT_POLL", {}, ("JOINT_FEEDBACK",), self.feedback))

    def feedback(self, src: int, name: str, f: dict) -> None:
        bits = self.ctx.spec.flags["LEG_FLAGS"].bits
        if f["current"] < BLOCK_CURRENT_MA or self.seg is None:
            return
        self.flags |= bits["BLOCKED"]
        self.ctx.event("blocked", self.now, self.leg)
        if self.retried:
            return
        # seed 6.1: retract the leg and compute a new trajectory, lifted to the step limit
        self.retried = True
        p = self.ctx.params
        start, end, lift, t0, dur = self.seg
        left = max(0.2, t0 + dur - self.now)
        back = (self.pos[0] + 0.3 * (start[0] - self.pos[0]), self.pos[1] + 0.3 * (start[1] - self.pos[1]), 0.0)
        self.seg = (back, end, p.step_limit + 0.01, self.now, left)

    def on_leg_poll(self, bus: str, src: int, f: dict) -> None:
        p = self.ctx.params
        hx, hy = p.hip(self.leg)
        x, y, z = self.pos
        self.reply(bus, src, "LEG_REPORT", flags=self.flags, x=round((x - hx) * 10000), y=round((y - hy) * 10000),
                   z=round(z * 10000), servo_temp=round(self.ctx.scenario.ambient_temp))
