"""The MMC's gait generator (seed 3.2.3/3.2.4): foot targets in the body frame.

A gait is a duty factor plus a phase offset per leg (tripod, ripple, wave:
seed 3.2.3 Mov_Cmd 7..9). Every swing lasts one tripod half cycle; a leg
lifts off when the gait's phase reaches its offset + duty and lands where
the next stance starts, half a stroke ahead of its neutral point. Stance
feet all move with one rigid body motion (the direction's velocity), so
they never shear against each other; a stance foot about to leave its
workspace pauses the body until that leg has stepped (safety net).

Changing the gait or the direction (seed 3.2.3: a gait change keeps the
direction) never makes a foot jump: stance feet carry on from where they
are in the new direction at once, swinging feet re-aim their touchdown,
no new swing starts until every foot is down, and then the new gait's
phase is chosen to fit where the feet are (`_rephase`). Two direction
changes skip that wait, whose cost would depend on the phase the command
lands at: a reversal walks the pattern backwards in place (`_reverse`; the
next re-phase turns it the right way round again), and in the tripod and
ripple a change between straight lines keeps the rhythm (`_keeps_rhythm`).
Any other change costs a bounded time whatever the phase it lands at (issue 17;
seed 5.2: react now): the feet in the air land as soon as a short swing can,
the re-phase picks the phase and each side's lift-off order with the shortest
pause (`_rephase`: a turn reverses one side's strokes, so the fixed order no
longer fits), and while the body still waits for a foot the feet step faster
(`_catch_up`). A late lift-off never puts up feet the pattern keeps apart
(`_may_lift`).
With a leg lost (seed 6.3 allows one) the remaining five walk a wave over five legs with a
shorter stroke, the two feet on the lost leg's side spread to straddle it,
so that four feet on the ground always keep the body statically stable.
"""
from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from typing import NamedTuple

from arachnae_proto.enums import MovCmd

from behaviours import tuning as T
from behaviours.geometry import RobotGeometry
from behaviours.kinematics import swing_point

# Mov_Cmd values of seed 3.2.3, as plain ints (the generated enum is the source; ints are faster).
STOP, FORWARD, BACKWARD = int(MovCmd.STOP), int(MovCmd.FORWARD), int(MovCmd.BACKWARD)
TURN_RIGHT, TURN_LEFT = int(MovCmd.TURN_RIGHT), int(MovCmd.TURN_LEFT)
SIDESTEP_RIGHT, SIDESTEP_LEFT = int(MovCmd.SIDESTEP_RIGHT), int(MovCmd.SIDESTEP_LEFT)
TRIPOD, RIPPLE, WAVE = int(MovCmd.TRIPOD), int(MovCmd.RIPPLE), int(MovCmd.WAVE)
GAITS = (TRIPOD, RIPPLE, WAVE)
FIVE_LEGGED = 0                      # gait id of the five-legged wave (not a Mov_Cmd)

# (vx, vy, w) per direction: body-frame unit motion, x forward, y left, w counter-clockwise.
MOTION = {
    STOP: (0.0, 0.0, 0.0), FORWARD: (1.0, 0.0, 0.0), BACKWARD: (-1.0, 0.0, 0.0),
    TURN_RIGHT: (0.0, 0.0, -1.0), TURN_LEFT: (0.0, 0.0, 1.0),
    SIDESTEP_RIGHT: (0.0, -1.0, 0.0), SIDESTEP_LEFT: (0.0, 1.0, 0.0),
}


def _straight(cmd: int) -> bool:
    """A direction that moves the body along a straight line (not STOP, not a turn)."""
    vx, vy, w = MOTION[cmd]
    return w == 0.0 and (vx, vy) != (0.0, 0.0)


WAVE_ORDER = (3, 2, 1, 6, 5, 4)      # CHOICE: metachronal, rear to front, left side then right side


def pattern(gait: int, legs: tuple[int, ...]) -> tuple[float, dict[int, float]]:
    """Duty factor and per-leg phase offsets (phase at which the leg's stance begins).

    CHOICE: tripod 1-3-5 / 2-4-6; ripple: each side a rear-to-front wave, the sides half a cycle
    apart (two feet up at a time); wave: one foot up at a time in WAVE_ORDER. Five legs: a wave over
    the remaining legs in WAVE_ORDER (one foot up, four down).
    """
    if gait == TRIPOD:
        return 0.5, {1: 0.0, 3: 0.0, 5: 0.0, 2: 0.5, 4: 0.5, 6: 0.5}
    if gait == RIPPLE:     # the feet up together are never both front or both rear legs
        return 2 / 3, {3: 0.0, 4: 1 / 6, 2: 1 / 3, 6: 1 / 2, 1: 2 / 3, 5: 5 / 6}
    order = [leg for leg in WAVE_ORDER if leg in legs]
    n = len(order)
    return 1 - 1 / n, {leg: i / n for i, leg in enumerate(order)}


class BodyStep(NamedTuple):
    """How the stance feet carried the body over one gait-clock step, in the body frame at its start."""

    fwd_m: float
    left_m: float
    turn_rad: float


STILL = BodyStep(0.0, 0.0, 0.0)


@dataclass
class LegPlan:
    swing: bool = False
    pos: tuple[float, float] = (0.0, 0.0)    # stance: the foot now; swing: where it lifted off
    c: float = 0.0                           # stance: stroke coordinate, +1/2 front .. -1/2 back
    t0: float = 0.0                          # swing start (gait clock)
    dur: float = 0.0                         # swing duration (gait clock)
    end: tuple[float, float] = (0.0, 0.0)    # swing touchdown point
    lift: float = 0.0
    next_lift: float = 0.0                   # total gait phase of the next lift-off
    z0: float = 0.0                          # height at swing start
    cmd: int = STOP                          # the direction the swing's touchdown point was aimed for


class Gait:
    """The MMC's gait generator: set_command(), advance(dt), then target(leg) gives (x, y, z) in the body frame."""

    def __init__(self, p: RobotGeometry, legs: tuple[int, ...] | None = None):
        self.p = p
        self.legs = tuple(legs or p.legs)            # legs in the gait (a lost leg is dropped)
        self.lost: set[int] = set()
        self.command = STOP
        self.gait = TRIPOD                           # the Mov_Cmd gait (what STATUS_ACK reports)
        self.running = TRIPOD                        # the pattern walking now (FIVE_LEGGED after a loss)
        self.t = 0.0                                 # gait clock, s
        self.phase = 0.0                             # total gait phase (cycles)
        self.scale = 1.0                             # gait clock speed (slowed on servo over-temperature)
        self.pending = True                          # re-phase when every foot is down
        self.paused = False
        self.gait_switches = 0
        self.pause_s = 0.0
        self.dt = T.MMC_CONTROL_S                    # the last clock step (gait seconds); the MMC steps at this period
        self.moved = STILL                           # the body's motion over the last step (the gait's own geometry)
        self.swing_lift = p.lift                     # how high the next swings lift (raised near an obstacle)
        self.plans = {leg: LegPlan(pos=p.neutral_foot(leg)) for leg in p.legs}
        self._set_pattern(TRIPOD)

    # --- pattern and geometry ------------------------------------------------------------
    def _set_pattern(self, gait: int) -> None:
        self.running = gait
        self.duty, self.offset = pattern(gait, self.legs)
        self.t_swing = self.p.half_cycle                    # every swing lasts one tripod half cycle
        self.cycle = self.t_swing / (1 - self.duty)
        self.t_stance = self.duty * self.cycle
        self.stroke = self.p.stroke * (T.GAIT_FIVE_LEG_STROKE if self.lost else 1.0)
        self.max_up = round(len(self.legs) * (1 - self.duty))

    def neutral(self, leg: int) -> tuple[float, float]:
        """The leg's neutral foot point; with a leg lost, the two feet left on its side straddle the gap."""
        nx, ny = self.p.neutral_foot(leg)
        if self.lost:
            side = self.p.side(leg)
            mates = sorted((lg for lg in self.legs if self.p.side(lg) == side), key=lambda lg: -self.p.hip(lg)[0])
            if len(mates) == 2 and any(self.p.side(lost) == side for lost in self.lost):
                spread = self.p.hip_x[0] * T.GAIT_FIVE_LEG_SPREAD
                nx = spread if leg == mates[0] else -spread
        return nx, ny

    def path(self, leg: int, c: float, cmd: int | None = None) -> tuple[float, float]:
        """Stance path: where the foot is at stroke coordinate c (+1/2 touchdown .. -1/2 lift-off)."""
        vx, vy, w = MOTION[self.command if cmd is None else cmd]
        nx, ny = self.neutral(leg)
        a = c * self.p.turn_stroke_rad * w
        ca, sa = math.cos(a), math.sin(a)
        return (ca * nx - sa * ny + c * self.stroke * vx, sa * nx + ca * ny + c * self.stroke * vy)

    def _project(self, leg: int, pos: tuple[float, float]) -> float:
        """Stroke coordinate of the path point nearest to pos (after a change of direction)."""
        best, best_c = math.inf, 0.0
        for i in range(-50, 51):
            c = i / 50
            x, y = self.path(leg, c)
            d = (x - pos[0]) ** 2 + (y - pos[1]) ** 2
            if d < best:
                best, best_c = d, c
        return best_c

    def _move(self, pos: tuple[float, float], dc: float) -> tuple[float, float]:
        """A stance foot after the body moved dc strokes: one rigid motion for every stance foot."""
        vx, vy, w = MOTION[self.command]
        a = -dc * self.p.turn_stroke_rad * w
        ca, sa = math.cos(a), math.sin(a)
        x, y = pos
        return (ca * x - sa * y - dc * self.stroke * vx, sa * x + ca * y - dc * self.stroke * vy)

    # --- commands ------------------------------------------------------------------------
    def set_command(self, cmd: int) -> None:
        """Apply a Mov_Cmd: 0..6 set the direction, 7..9 the gait (seed 3.2.3)."""
        if cmd in GAITS:
            if cmd != self.gait and not self.lost:     # CHOICE: on five legs only the five-legged wave
                self.gait = cmd
                self.gait_switches += 1
                self.pending = True          # seed 3.2.3: the direction stays; the feet re-phase when all are down
            return
        if cmd not in MOTION or cmd == self.command:
            return
        if self._reversal(cmd):
            self._reverse(cmd)
            return
        was, self.command = self.command, cmd
        # react now (seed 5.2): stance feet carry on in the new direction from where they are,
        # swinging feet re-aim their touchdown; the phase is re-fitted once every foot is down,
        # unless the pattern can walk on in its rhythm
        wait = self.pending or not self._keeps_rhythm(cmd, was)
        for leg in self.legs:
            pl = self.plans[leg]
            if pl.swing:
                left = pl.t0 + pl.dur - self.t
                if left >= T.GAIT_MIN_SWING * self.t_swing:   # else it lands where it aimed
                    x, y, z = self.target(leg)                  # re-aimed from where it is (as the LCP does)
                    pl.end = self.path(leg, 0.5) if cmd != STOP else self.neutral(leg)
                    if wait:     # the stance feet drift while it flies: land as soon as a short swing could (issue 17)
                        left = max(self._fly_time((x, y), pl.end), T.GAIT_MIN_SWING * left)
                    pl.pos, pl.z0, pl.t0, pl.dur = (x, y), z, self.t, left
                    pl.cmd = cmd
            else:
                pl.c = self._project(leg, pl.pos) if cmd != STOP else 0.0
        self.pending = wait

    def _keeps_rhythm(self, cmd: int, was: int) -> bool:
        """Walk on in the running pattern (no wait for every foot down) after a change from `was` to `cmd`.

        From one straight line to another each stance foot projects to about the middle of its new
        stroke, so keeping the rhythm lets a foot overrun at most 1/2 - GAIT_OVERRUN strokes (one due a
        whole stroke later). Waiting for the swinging feet to land instead lets every stance foot drift
        t_swing / t_stance strokes towards its rear limit at once, and the pause then depends on where in
        the cycle the command came (issue 17): the rhythm is kept where that drift is the larger (tripod,
        ripple; the wave lifts one foot at a time and waits). A start, a stop or a turn (the feet scatter
        along their new arcs) re-phases once every foot is down.
        """
        return _straight(cmd) and _straight(was) and self._waiting_drifts_far()

    def _waiting_drifts_far(self) -> bool:
        """Waiting for the swinging feet to land drifts the stance feet further than keeping the rhythm overruns."""
        return self.t_swing / self.t_stance > 0.5 - T.GAIT_OVERRUN

    def _reversal(self, cmd: int) -> bool:
        """The new direction is the old one backwards, and the pattern is in step (not awaiting a re-phase)."""
        if self.pending or STOP in (cmd, self.command):
            return False
        return all(a == -b for a, b in zip(MOTION[cmd], MOTION[self.command]))

    def _reverse(self, cmd: int) -> None:
        """Walk the pattern backwards in place (seed 3.2.3: no foot jumps; seed 5.2: react now).

        Backwards, the stroke coordinates flip (c -> -c: the foot that just landed is now at the rear)
        and so does the order of lift-offs: with the offsets negated and the phase phi -> duty - phi,
        every leg's place in its cycle is mirrored (u -> duty - u), which is exactly where its foot
        is. No foot waits for the others to land, so a reversal costs the same whatever the phase.
        """
        self.command = cmd
        stance_so_far = {leg: min((self.phase - o) % 1.0, self.duty) for leg, o in self.offset.items()}   # late: a whole stance
        self.offset = {leg: -o % 1.0 for leg, o in self.offset.items()}
        self.phase = math.floor(self.phase) + 1.0 + (self.duty - self.phase) % 1.0
        for leg in self.legs:
            pl = self.plans[leg]
            if pl.swing:                               # flies back to where it lifted off in what its swing has taken so far
                x, y, z = self.target(leg)
                end = self.path(leg, 0.5)
                # its own clock (the phase may call it landed a tick early), but no faster than the shortest
                # swing: a foot that lifted with stroke to spare (`_catch_up`) has further to fly back
                left = max(self.t - pl.t0, self.dt, self._fly_time((x, y), end))
                if left < T.GAIT_MIN_SWING * self.t_swing:    # barely lifted: straight back down, no higher
                    pl.lift = z
                pl.pos, pl.z0, pl.t0, pl.dur = (x, y), z, self.t, left
                pl.end, pl.cmd = end, cmd
                pl.next_lift = self.phase + left / self.cycle + self.duty
            else:
                pl.c = -pl.c     # back to its new rear end in what its stance took; a foot that landed before its
                # place in the pattern (a short swing) has taken less: its own stroke says how much (issue 17)
                pl.next_lift = self.phase + min(stance_so_far[leg], (pl.c + 0.5) * self.duty)

    def drop_leg(self, leg: int) -> None:
        """A leg is lost (seed 6.3: five of six suffice): walk the five-legged wave from the next all-feet-down."""
        if leg in self.lost or leg not in self.legs:
            return
        self.lost.add(leg)
        self.legs = tuple(lg for lg in self.legs if lg != leg)
        self.gait = WAVE                             # STATUS_ACK: a wave over five legs
        self.pending = True

    # --- clock -------------------------------------------------------------------------------
    def advance(self, dt: float) -> None:
        """One gait-clock step: touchdowns, the re-phase once every foot is down, lift-offs, then the body motion."""
        dt *= self.scale
        self.dt = dt
        self.moved = STILL
        # events at the start of the step, then the motion over it
        for leg in self.legs:                                  # touchdowns first
            pl = self.plans[leg]
            if pl.swing and self.t >= pl.t0 + pl.dur - dt / 2:      # lands on the tick nearest its time
                pl.swing, pl.pos, pl.z0 = False, pl.end, 0.0
                if self.command == STOP:
                    pl.c = 0.0
                else:
                    pl.c = 0.5 if pl.cmd == self.command else self._project(leg, pl.pos)
        if self.pending and not any(self.plans[leg].swing for leg in self.legs):
            self.pending = False
            want = FIVE_LEGGED if self.lost else self.gait
            if want != self.running:
                self._set_pattern(want)
                for leg in self.legs:                          # new neutral points and stroke
                    self.plans[leg].c = self._project(leg, self.plans[leg].pos)
            if self.command != STOP:
                self._rephase()
        self.t += dt
        if self.command == STOP:
            return
        if not self.pending:                                   # no new swing until every foot is down
            up = sum(1 for leg in self.legs if self.plans[leg].swing)
            for leg in sorted(self.legs, key=lambda lg: self.plans[lg].next_lift):   # the most overdue first
                pl = self.plans[leg]
                due = self.phase >= pl.next_lift - 0.5 * dt / self.cycle      # on the tick nearest its time
                if not pl.swing and due and up < self.max_up and self._may_lift(leg):   # never more feet up than the pattern lifts
                    up += 1
                    late = max(0.0, (self.phase - pl.next_lift) * self.cycle)
                    swing = self.t_swing / (self._catch_up() if self.paused else 1.0)
                    self._lift(leg, max(self.t_swing * T.GAIT_MIN_SWING, swing - late))
                    while pl.next_lift - 0.5 * dt / self.cycle <= self.phase:
                        pl.next_lift += 1.0
        self.phase += dt / self.cycle * (self._catch_up() if self.paused else 1.0)
        # stance: one rigid body motion for every stance foot, unless one would leave its workspace
        dc = dt / self.t_stance
        stance = [self.plans[leg] for leg in self.legs if not self.plans[leg].swing]
        self.paused = any(pl.c - dc < -0.5 - T.GAIT_OVERRUN for pl in stance)
        if self.paused:
            self.pause_s += dt
        else:
            for pl in stance:
                pl.pos = self._move(pl.pos, dc)
                pl.c -= dc
            vx, vy, w = MOTION[self.command]
            self.moved = BodyStep(dc * self.stroke * vx, dc * self.stroke * vy, dc * self.p.turn_stroke_rad * w)

    def _fly_time(self, start: tuple[float, float], end: tuple[float, float]) -> float:
        """The least time (gait s) a swing may take from start to end: a stroke in the shortest swing's time."""
        return math.dist(start, end) / self.stroke * T.GAIT_MIN_SWING * self.t_swing

    def _may_lift(self, leg: int) -> bool:
        """Every foot in the air is one the pattern lifts together with this one (a late lift-off after a
        re-phase, a reversal or a pause may not put up two feet the pattern keeps apart): the tripod's own
        group; otherwise never two of one side, nor both front or both rear legs (`pattern`)."""
        hx = self.p.hip(leg)[0]
        for other in self.legs:
            if other != leg and self.plans[other].swing:
                if self.running == TRIPOD:
                    if self.offset[other] != self.offset[leg]:
                        return False
                elif self.p.side(other) == self.p.side(leg) or self.p.hip(other)[0] == hx:
                    return False
        return True

    def _catch_up(self) -> float:
        """How much faster the pattern's clock runs, and swings started then are, while the body waits for a
        foot to get out of the way (issue 17: the wait after a re-phase is that much shorter).

        Stance feet do not move meanwhile, so every leg keeps its place in the pattern; a short swing still in
        the air when the body walks on lands early and its stance then runs past the stroke's rear end by at
        most what the swing saved, which must stay within GAIT_OVERRUN: so (1 - 1/k) t_swing <= GAIT_OVERRUN
        t_stance, and never shorter than the shortest swing (tripod 1.18x, ripple 1.43x, wave 2x).
        """
        room = 1.0 - T.GAIT_OVERRUN * self.t_stance / self.t_swing
        return 1.0 / max(T.GAIT_MIN_SWING, room)

    def _lift(self, leg: int, dur: float) -> None:
        pl = self.plans[leg]
        pl.swing, pl.t0, pl.dur, pl.z0 = True, self.t - self.dt, dur, 0.0   # the step began this tick
        pl.end, pl.cmd = self.path(leg, 0.5), self.command
        pl.lift = self.swing_lift

    def _rephase(self) -> None:
        """Choose the phase, and the lift-off order within each side, that fit where the stance feet are.

        A turn after a straight line (or the other way round) reverses one side's strokes, so that
        side's feet stand in the order opposite to the pattern's: no phase of the fixed order fits, and
        the body paused until the foot due last had stepped, 0-2.6 s of a 4 s wave turn depending on the
        phase the key came at (issue 17). Each side's legs may take each other's places in the pattern
        (`_orders`): the feet up together stay as many, and on different sides, as the pattern has.
        """
        best, best_phi, best_offset = math.inf, 0.0, self.offset
        for offset in self._orders():
            for i in range(T.GAIT_REPHASE_STEPS):
                phi = i / T.GAIT_REPHASE_STEPS
                us = [(self.plans[leg].c, (phi - offset[leg]) % 1.0) for leg in self.legs]
                cost = T.GAIT_PAUSE_WEIGHT * max(self._wait(c, u) for c, u in us) + sum(self._fit(c, u) for c, u in us)
                if cost < best - 1e-12:
                    best, best_phi, best_offset = cost, phi, offset
        self.offset = best_offset
        self.phase = math.floor(self.phase) + 1.0 + best_phi
        for leg in self.legs:
            pl = self.plans[leg]
            u = (best_phi - self.offset[leg]) % 1.0
            pl.next_lift = self.phase - (u - self.duty) if u >= self.duty else self.phase + (self.duty - u)

    def _wait(self, c: float, u: float) -> float:
        """How long (gait s) the body must pause for a foot at stroke coordinate c in place u to lift in time.

        It lifts (duty - u) cycles from now (now, if u is past the duty) and runs out of stroke when the body
        has moved c + 1/2 + GAIT_OVERRUN strokes; the pauses add up, so the largest of these is the pattern's.
        A foot lifting now with less than the shortest swing left of its place stays up that much longer than
        the pattern says, holding back the next lift-off by as much.
        """
        if u >= self.duty:
            return max(0.0, T.GAIT_MIN_SWING - (1.0 - u) / (1.0 - self.duty)) * self.t_swing
        return max(0.0, (self.duty - u) * self.cycle - (c + 0.5 + T.GAIT_OVERRUN) * self.t_stance)

    def _fit(self, c: float, u: float) -> float:
        """Cost of a foot at stroke coordinate c taking the place u (cycles since its stance began) in the pattern."""
        if u < self.duty:                            # stance, (1 - s) strokes before lift-off
            s = u / self.duty
            over = max(0.0, -0.5 - (c - (1 - s)))
            return T.GAIT_OVERRUN_WEIGHT * over * over + (c - (0.5 - s)) ** 2
        s = (u - self.duty) / (1 - self.duty)        # would lift now, with what is left of its swing
        return (T.GAIT_OVERRUN_WEIGHT if 1 - s < T.GAIT_MIN_SWING else 0.0) + (c + 0.5) ** 2 + s * s

    def _orders(self) -> list[dict[int, float]]:
        """The running pattern's offsets (first: kept on a tie), then each side's legs in every order of its places.

        Only patterns with one foot up per side at a time (ripple, wave) are reordered, and only where the
        feet up together are still never both front or both rear legs (`pattern`); the tripod's groups and
        the five-legged wave's straddle stay as they are.
        """
        base = pattern(self.running, self.legs)[1]     # the right way round again after a reversal
        if self.running not in (RIPPLE, WAVE):
            return [base]
        sides = [[leg for leg in self.legs if self.p.side(leg) == sd] for sd in (1.0, -1.0)]
        up = 1 - self.duty - 1e-9
        orders = [base]
        for left in itertools.permutations(sides[0]):
            for right in itertools.permutations(sides[1]):
                offset = {leg: base[slot] for legs, slots in ((left, sides[0]), (right, sides[1]))
                          for leg, slot in zip(legs, slots)}
                together = [(a, b) for a, b in itertools.combinations(self.legs, 2)
                            if min((offset[a] - offset[b]) % 1.0, (offset[b] - offset[a]) % 1.0) < up]
                if offset != base and all(self.p.hip(a)[0] != self.p.hip(b)[0] for a, b in together):
                    orders.append(offset)
        if self.max_up == 1:       # one foot up at a time: any order keeps five down; the nearest its rear end first
            urgent = sorted(self.legs, key=lambda leg: self.plans[leg].c)
            orders.append({leg: base[slot] for leg, slot in zip(urgent, sorted(base, key=base.__getitem__))})
        return orders

    def set_scale(self, scale: float) -> None:
        """Slow the whole gait down (servo over-temperature) or back to full speed."""
        self.scale = scale

    # --- what the legs are told ------------------------------------------------------------------
    def target(self, leg: int) -> tuple[float, float, float]:
        """Where the foot is now: (x, y, height) in the body frame."""
        pl = self.plans[leg]
        if not pl.swing:
            return (pl.pos[0], pl.pos[1], 0.0)
        s = min(1.0, (self.t - pl.t0) / pl.dur) if pl.dur > 0 else 1.0
        return swing_point((pl.pos[0], pl.pos[1], pl.z0), pl.end, pl.lift, s, T.LCP_SWING_EDGE)

    def segment(self, leg: int) -> tuple[bool, tuple[float, float], float, float]:
        """(swing, end point, lift, gait seconds left) of the leg's current segment.

        Stance: the point where the foot will lift off if the body keeps moving (held: where it is).
        """
        pl = self.plans[leg]
        if pl.swing:
            return True, pl.end, pl.lift, max(0.0, pl.t0 + pl.dur - self.t)
        if self.command == STOP or self.paused:
            return False, pl.pos, 0.0, 0.0
        # until the re-phase the lift-off is not known: aim at the end of the foot's workspace
        # whole ticks: the foot lifts on the tick nearest its time
        left = math.inf if self.pending else max(0.0, round((pl.next_lift - self.phase) * self.cycle / self.dt) * self.dt)
        dc = max(0.0, min(left / self.t_stance, pl.c + 0.5 + T.GAIT_OVERRUN))
        return False, self._move(pl.pos, dc), 0.0, dc * self.t_stance

    def in_swing(self, leg: int) -> bool:
        return self.plans[leg].swing

    def speed(self) -> tuple[float, float]:
        """Nominal body speed (m/s) and turn rate (rad/s) of the running pattern at full scale."""
        return self.stroke / self.t_stance, self.p.turn_stroke_rad / self.t_stance
