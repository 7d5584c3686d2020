"""LCP(n) (seed 3.2.10): one leg's trajectory, its three servos, and its local reflexes.

From a LEG_TARGET it moves the foot from where it is to the target: a
straight line in stance, hold and retract; in swing a lift-off / transfer /
touch-down profile (behaviours.kinematics.swing_point). Every control period
the foot point goes through the inverse kinematics to JOINT_TARGETs; an
unchanged set point is repeated every `setpoint_refresh_ms` (spec protocol).

It polls its JACs in turn (seed 3.2.10: the LCP does the leg's own sensor
processing, for speed):
- motor current above the limit during a swing: the leg is blocked (seed
  6.1): retract the foot, lift it to the step limit and try again; blocked
  again during that retry: the drive has failed (STATUS_ACK OUT_OF_ORDER,
  seed 3.2.10 "kann sein Bein nicht mehr steuern (blockiert ...)") and the
  foot is set down where the swing began. BLOCKED clears after a clean swing.
  Stall current outside a swing (a foot set down, held or hovering against a
  wall) for LCP_STALL_HOLD_S: the foot stops where the JACs report it (servo
  protection; the leg's flags are left to the swing's rule). The stall is the
  leg's: any of its JACs reporting stall current, with gaps no longer than
  LCP_STALL_GAP_S (a foot scraping a wall stalls and slips by turns).
- a JAC that stops answering: LEG_FLAGS.JAC_FAULT, OUT_OF_ORDER.
- a JAC reporting OVERTEMP: LEG_FLAGS.OVERTEMP (the MMC slows the gait).
The sole switch is read locally (seed 1.2.2): a carrying foot without ground
contact first searches down for the ground (up to LCP_GROUND_SEARCH_M below its
set point: the body may stand on a foot that rests on a low obstacle); still
without contact LCP_SETTLE_S after touchdown it reports NO_GROUND and hovers at
LCP_NO_GROUND_Z_M instead of pushing down into the pit; the flag clears
when the sole touches ground again, or the foot swings to land elsewhere. A foot
that did not get down (its JACs put it above LCP_GROUND_REACHED_M: it rests
against a wall's or an obstacle's face) is not over a pit.
"""
from __future__ import annotations

import math
from typing import TypedDict

from arachnae_proto import messages as M
from arachnae_proto.enums import JointFlags, LegFlags, LegPhase, OrderStatus
from arachnae_proto.skeletons.lcp import LcpSkeleton
from arachnae_proto.network import NODES

from behaviours import tuning as T
from behaviours.kinematics import fk, ik, swing_point
from behaviours.post import PostMaster
from behaviours.runtime import Runtime, slaves_of
from behaviours.units import quantizer

_MM = quantizer(M.LegTarget, "x")
_DEG = quantizer(M.JointTarget, "angle")
_DEG_S = quantizer(M.JointTarget, "speed")
_TEMP = quantizer(M.LegReport, "servo_temp")
_FB_DEG = quantizer(M.JointFeedback, "angle")
_CONTACT, _BLOCKED = int(LegFlags.CONTACT), int(LegFlags.BLOCKED)
_NO_GROUND, _SWINGING = int(LegFlags.NO_GROUND), int(LegFlags.SWINGING)
_OVERTEMP, _JAC_FAULT = int(LegFlags.OVERTEMP), int(LegFlags.JAC_FAULT)
_J_OVERTEMP = int(JointFlags.OVERTEMP)
_STANCE, _SWING, _RETRACT, _HOLD = int(LegPhase.STANCE), int(LegPhase.SWING), int(LegPhase.RETRACT), int(LegPhase.HOLD)
_DEG_PER_RAW = _DEG.phys(1)                  # JOINT_TARGET angle resolution
_TOP_SPEED = _DEG_S.phys(_DEG_S.hi)         # the speed field's maximum


class Segment:
    """One piece of foot trajectory: from `start` to `end` (x, y, z) in `dur` seconds from `t0`."""

    __slots__ = ("start", "end", "lift", "t0", "dur", "swing", "blocked")

    def __init__(self, start: tuple, end: tuple, t0: float, dur: float, swing: bool = False, lift: float = 0.0):
        self.start, self.end, self.t0, self.dur = start, end, t0, dur
        self.swing, self.lift, self.blocked = swing, lift, False

    def progress(self, t: float) -> float:
        return 1.0 if self.dur <= 0 else min(1.0, max(0.0, (t - self.t0) / self.dur))

    def at(self, t: float) -> tuple[float, float, float]:
        s = self.progress(t)
        if self.swing:
            return swing_point(self.start, self.end[:2], self.lift, s, T.LCP_SWING_EDGE)
        x, y = (a + (b - a) * s for a, b in zip(self.start[:2], self.end[:2]))
        z0, z1 = self.start[2], self.end[2]
        if z1 == 0.0 and z0 > 0.0:            # a stance begun in the air: set the foot down first, quickly
            u = min(1.0, (t - self.t0) / T.LCP_SET_DOWN_S)
            return (x, y, z0 * (1.0 - u * u * (3.0 - 2.0 * u)))
        return (x, y, z0 + (z1 - z0) * s)

    def done(self, t: float) -> bool:
        return t >= self.t0 + self.dur


class LcpDebug(TypedDict):
    """LCP.debug_metrics(): metrics.json `nodes.<LCP>` (sim2d.metrics checks expectations on it at load)."""
    flags: int
    blocked_events: int
    stall_holds: int
    failed: bool
    dead_jacs: int


class LCP(PostMaster, Runtime, LcpSkeleton):
    def start(self) -> None:
        g = self.cfg.geometry
        self.leg = NODES[self.address].leg
        self.jacs = sorted(slaves_of(self.master_bus), key=lambda a: NODES[a].joint)
        nx, ny = g.neutral_foot(self.leg)
        self.pos = (nx, ny, 0.0)
        self.target: tuple | None = None      # (phase, x, y, z) raw of the LEG_TARGET being executed
        self.seg: Segment | None = None
        self.phase = -1
        self.flags = 0
        self.retried = False                  # seed 6.1: this swing has been re-planned once
        self.failed = False                   # blocked again after the retry: leg drive failed
        self.touchdown = 0.0                  # when the foot last came down (end of a swing, or a stance began)
        self.lost_contact = 0.0               # the last time the sole switch was closed
        self.search_z = 0.0                   # how far below its set point the carrying foot reaches for ground
        self.high_steps = 0                   # swings still lifted to the step limit after a block
        self.deferred: Segment | None = None  # a stance that waits for a re-planned swing to land
        self.poll_i = 0
        self.misses: dict[int, int] = {}
        self.dead_jacs: set[int] = set()
        self.hot: set[int] = set()
        self.sent_angles: dict[int, int] = {}
        self.sent_at: dict[int, float] = {}
        self.servo_temp: dict[int, float] = {}
        self.measured: dict[int, float] = {}  # joint -> the angle (rad) its JAC last reported
        self.stall_start = -math.inf          # the leg's stall outside a swing: when it began, when last reported
        self.stall_seen = -math.inf
        self.blocked_events = 0
        self.stall_holds = 0                  # feet stopped by stall current outside a swing
        self.run_post(self.post_done)
        self.every(T.LCP_CONTROL_S, self.tick)

    def post_done(self, missing: list[int]) -> None:
        for a in self.jacs:                   # one feedback each: the servo temperatures for LEG_REPORT
            if a not in missing:
                self.poll(a)

    def live_jacs(self) -> list[int]:
        return [a for a in self.jacs if a not in (self.post_missing or ()) and a not in self.dead_jacs]

    # --- targets from the MMC ---------------------------------------------------------------
    def on_leg_target(self, src: int, msg: M.LegTarget) -> None:
        key = (msg.phase, msg.x, msg.y, msg.z)
        if key == self.target and self.seg is not None:
            return                            # a refresh of the target being executed (spec setpoint_refresh_ms)
        hx, hy = self.cfg.geometry.hip(self.leg)
        x, y, z = _MM.phys(msg.x) / 1000 + hx, _MM.phys(msg.y) / 1000 + hy, _MM.phys(msg.z) / 1000
        old = self.seg
        self.target, self.phase = key, msg.phase
        dur = msg.duration / 1000
        self.deferred = None
        if msg.phase == _SWING:
            self.flags &= ~_NO_GROUND         # the foot steps elsewhere: where it lands is judged anew
            in_air = old is not None and old.swing
            if self.high_steps > 0 and not in_air:
                self.high_steps -= 1
                z = max(z, self.high_lift())
            self.seg = Segment(self.pos, (x, y, 0.0), self.now, dur, swing=True, lift=z)
            self.seg.blocked = in_air and old.blocked         # a re-aimed swing keeps its block history
            self.retried = in_air and self.retried
            return
        end = (x, y, z if msg.phase in (_RETRACT, _HOLD) else 0.0)
        if old is not None and old.swing and old.blocked and not old.done(self.now):
            # seed 6.1: the re-planned swing lands first; the stance then catches up by its end time
            self.deferred = Segment(old.end, end, old.t0 + old.dur, max(0.0, self.now + dur - old.t0 - old.dur))
            return
        if old is None or old.swing:
            self.end_swing(self.now)
        self.seg = Segment(self.pos, end, self.now, dur)

    def end_swing(self, t: float) -> None:
        """The foot comes down: the ground-contact check starts; a clean step ends a block (seed 6.1)."""
        seg = self.seg
        self.touchdown = t
        self.search_z = 0.0
        if seg is not None and seg.swing and not seg.blocked:
            self.flags &= ~_BLOCKED
            self.failed = False
        self.retried = False

    def carrying(self) -> bool:
        """The foot is meant to be on the ground (stance or hold at ground level)."""
        return self.phase in (_STANCE, _HOLD) and self.seg is not None and not self.seg.swing and self.seg.end[2] == 0.0

    # --- control period ---------------------------------------------------------------------
    def tick(self) -> None:
        if self.post_missing is None:
            return
        t = self.now
        period = T.LCP_CONTROL_S
        seg = self.seg
        if seg is not None and seg.swing and seg.done(t):
            self.end_swing(seg.t0 + seg.dur)
            seg = self.seg = self.deferred or Segment(seg.end, seg.end, seg.t0 + seg.dur, 0.0)   # landed
            self.deferred = None
        contact = self.hw.sole_contact()
        self.flags = (self.flags | _CONTACT) if contact else (self.flags & ~_CONTACT)
        swinging = seg is not None and seg.swing and not seg.done(t)
        self.flags = (self.flags | _SWINGING) if swinging else (self.flags & ~_SWINGING)
        searched = self.search_z <= -T.LCP_GROUND_SEARCH_M + 1e-9
        if contact:
            self.flags &= ~_NO_GROUND
            self.lost_contact = t
        elif self.carrying() and not self.flags & _NO_GROUND and not searched:
            # reach down for the ground before calling it a pit (a sole switch only sees touch)
            self.search_z = max(-T.LCP_GROUND_SEARCH_M, self.search_z - T.LCP_GROUND_SEARCH_M_S * period)
        elif (self.carrying() and t - max(self.touchdown, self.lost_contact) > T.LCP_SETTLE_S
              and not self.flags & _NO_GROUND and self.measured_foot()[2] <= T.LCP_GROUND_REACHED_M):
            # seed 1.2.2: the sole finds no ground (a pit) where the foot got down to; a foot held up above
            # that (on an obstacle's face: its JACs say where it is) is not over a pit (issue 17/18)
            self.flags |= _NO_GROUND
            self.hw.note("no_ground", leg=self.leg)
        x, y, z = seg.at(t + period) if seg is not None else self.pos
        if self.carrying() and not self.flags & _NO_GROUND:
            z += self.search_z
        if self.flags & _NO_GROUND and self.carrying() and t - self.touchdown > T.LCP_SETTLE_S:
            z = max(z, T.LCP_NO_GROUND_Z_M)   # over a pit: no weight on this leg, the foot hovers
        self.pos = (x, y, z)
        self.command(t, period)
        live = self.live_jacs()
        if live:                              # every JAC in turn; during a swing one more (seed 6.1: fast)
            for _ in range(2 if swinging else 1):
                missed = [a for a in live if self.misses.get(a, 0)]
                if missed:
                    self.poll(missed[0])          # one that missed its last poll is asked again first
                else:
                    self.poll(live[self.poll_i % len(live)])
                    self.poll_i += 1

    def command(self, t: float, period: float) -> None:
        q = ik(self.cfg.geometry, self.leg, *self.pos)
        refresh = self.net.protocol.setpoint_refresh_s
        for a in self.live_jacs():
            joint = NODES[a].joint
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

    # --- JAC feedback -------------------------------------------------------------------------
    def poll(self, a: int) -> None:
        self.request(a, M.JointPoll(), (M.JointFeedback,), self.feedback, lambda a=a: self.no_answer(a))

    def no_answer(self, a: int) -> None:
        """A JAC that misses LCP_JAC_TIMEOUTS polls in a row is out of order: the leg reports JAC_FAULT."""
        self.misses[a] = self.misses.get(a, 0) + 1
        if self.misses[a] >= T.LCP_JAC_TIMEOUTS and a not in self.dead_jacs:
            self.dead_jacs.add(a)
            self.flags |= _JAC_FAULT
            self.hw.note("jac_fault", leg=self.leg, jac=a)

    def feedback(self, src: int, fb: M.JointFeedback) -> None:
        self.misses[src] = 0
        self.servo_temp[src] = fb.temperature
        self.measured[NODES[src].joint] = math.radians(_FB_DEG.phys(fb.angle))
        if fb.flags & _J_OVERTEMP:
            if not self.hot:
                self.hw.note("servo_overtemp", leg=self.leg, jac=src)
            self.hot.add(src)
        else:
            self.hot.discard(src)
        self.flags = (self.flags | _OVERTEMP) if self.hot else (self.flags & ~_OVERTEMP)
        seg = self.seg
        if fb.current < T.LCP_BLOCK_CURRENT_A * 1000:
            return
        if seg is None or not seg.swing or seg.done(self.now):
            # issue 18: one JAC's clean reading does not end the leg's stall (its joints stall and slip by
            # turns against a wall); a whole round of polls without stall current does
            if self.now - self.stall_seen > T.LCP_STALL_GAP_S:
                self.stall_start = self.now
            self.stall_seen = self.now
            if self.now - self.stall_start >= T.LCP_STALL_HOLD_S:
                self.halt_stalled()
            return
        if self.retried and self.now - seg.t0 < T.LCP_RETRY_GRACE_S:
            return                            # the retract has only just begun: that current is the old stall
        seg.blocked = True
        self.flags |= _BLOCKED
        self.blocked_events += 1
        self.hw.note("blocked", leg=self.leg)
        r = T.LCP_RETRACT
        x, y, _ = self.pos
        if self.retried:
            # blocked again after the re-plan: the drive has failed; set the foot down where the swing began
            self.failed = True
            self.seg = Segment(self.pos, (seg.start[0], seg.start[1], 0.0), self.now, T.LCP_RETRY_MIN_S)
            self.seg.blocked = True
            return
        # seed 6.1: retract the leg and compute a new trajectory: straight up to the step limit
        # from a point pulled back towards the lift-off, over, and down; the next swings step high too
        self.retried = True
        self.high_steps = T.LCP_HIGH_STEPS
        left = max(T.LCP_RETRY_MIN_S, seg.t0 + seg.dur - self.now)
        back = (x + r * (seg.start[0] - x), y + r * (seg.start[1] - y), self.pos[2])
        self.seg = Segment(back, seg.end, self.now, left, swing=True, lift=self.high_lift())
        self.seg.blocked = True

    def measured_foot(self) -> tuple[float, float, float]:
        """The foot where its JACs last reported their angles (a joint not polled yet: where it was sent)."""
        q = list(ik(self.cfg.geometry, self.leg, *self.pos))
        for joint, angle in self.measured.items():
            q[joint - 1] = angle
        return fk(self.cfg.geometry, self.leg, *q)

    def halt_stalled(self) -> None:
        """seed 3.2.10: the LCP watches for collisions along the whole trajectory, not only in a swing (6.1).
        A foot that stalls while it is set down, held or hovering stops where its JACs say it is: a servo
        left pushing at stall current cooks its motor and drags the battery voltage under the PSC's alarm
        limit (issue 18). The next LEG_TARGET starts from here. No BLOCKED flag: that is the swing's rule
        (6.1), and a flag would make the NP3 step aside at every touch of a set-down foot."""
        self.stall_start = self.stall_seen = -math.inf
        here = self.measured_foot()
        # a foot meant to carry is set down straight from there (down a wall's face, not hanging on it)
        end = (here[0], here[1], 0.0) if self.carrying() else here
        self.seg, self.deferred, self.pos = Segment(here, end, self.now, T.LCP_SET_DOWN_S), None, here
        self.stall_holds += 1
        self.hw.note("stall_hold", leg=self.leg)

    def high_lift(self) -> float:
        """seed 1.2.1: the highest obstacle a leg steps over is half the body height; a bit above it."""
        return self.cfg.geometry.step_limit + T.LCP_RETRY_CLEARANCE_M

    # --- reports ----------------------------------------------------------------------------------
    def on_leg_poll(self, src: int, msg: M.LegPoll) -> None:
        hx, hy = self.cfg.geometry.hip(self.leg)
        x, y, z = self.pos
        temp = max(self.servo_temp.values()) if self.servo_temp else 0.0
        self.send(src, M.LegReport(flags=self.flags, x=_MM.raw((x - hx) * 1000), y=_MM.raw((y - hy) * 1000),
                                   z=_MM.raw(z * 1000), servo_temp=_TEMP.raw(temp)))

    def status_ack(self) -> M.StatusAckOrder:
        """seed 3.2.10: OUT_OF_ORDER when the LCP can no longer control its leg (drive failed, JAC gone)."""
        bad = self.failed or bool(self.dead_jacs)
        return M.StatusAckOrder(status=int(OrderStatus.OUT_OF_ORDER if bad else OrderStatus.IN_ORDER))

    def debug_metrics(self) -> LcpDebug:
        """Debug port: the leg's flags and reflex counts at the end of a run."""
        return {"flags": self.flags, "blocked_events": self.blocked_events, "stall_holds": self.stall_holds,
                "failed": self.failed,
                "dead_jacs": len(self.dead_jacs)}
