"""MMC (seed 3.2.4): turns MOVE into a gait and sends each leg its next foot target.

The gait generator (behaviours.gait) runs on the MMC's clock; whenever a
leg's segment changes the MMC sends that leg's LCP a LEG_TARGET (end point
relative to the hip, phase, duration), and repeats an unchanged target every
`setpoint_refresh_ms` (spec protocol: targets are not acknowledged).

It polls the legs in turn for LEG_REPORT (every MMC_POLL_S: a pit is noticed
within about half a second) and keeps one error per leg (seed 3.2.4 error
codes; STATUS_ACK carries the most urgent one and its leg):
- no answer to MMC_LEG_TIMEOUTS polls: LCP_OUT_OF_ORDER; JAC_FAULT in the
  report: JAC_OUT_OF_ORDER. Either way the leg is lost and the other five
  walk the five-legged wave (seed 6.3: five legs suffice); a lost leg whose
  LCP still answers is held lifted and tucked in, out of the way. Lost stays
  lost until the next INIT/POST (CHOICE).
- BLOCKED (seed 6.1): LEG_DRIVE_BLOCKED, and every leg steps high (to the step
  limit) for MMC_HIGH_STEP_S, so the legs behind step over the obstacle; if the LCP then says OUT_OF_ORDER
  (its retry was blocked too): LEG_DRIVE_FAILED. Both clear with the first
  report without BLOCKED (the LCP clears it after a clean step).
- NO_GROUND (a pit, seed 1.2.2): the MMC stops at once (local safety, before
  the NP3 reacts) but takes the next MOVE (e.g. BACKWARD) as usual; the error
  clears when that foot has ground contact again.
- OVERTEMP: the gait runs at MMC_OVERTEMP_SCALE speed while any leg reports it.
CHOICE, most urgent first: NO_GROUND, LCP_OUT_OF_ORDER, JAC_OUT_OF_ORDER,
LEG_DRIVE_FAILED, LEG_DRIVE_BLOCKED (a pit needs the NP3 now; a lost leg is
old news once reported).
"""
from __future__ import annotations

from typing import TypedDict

from arachnae_proto import messages as M
from arachnae_proto.enums import Direction, Gait as GaitCode, LegFlags, LegPhase, MmcError, MovCmd, OrderStatus
from arachnae_proto.network import NODES
from arachnae_proto.skeletons.mmc import MmcSkeleton

from behaviours import tuning as T
from behaviours.gait import STOP, Gait
from behaviours.post import PostMaster, behind
from behaviours.runtime import Runtime, slaves_of
from behaviours.units import quantizer

_MM = quantizer(M.LegTarget, "x")          # mm on the wire (deci-mm raw)
_MS = quantizer(M.LegTarget, "duration")
_BLOCKED, _NO_GROUND = int(LegFlags.BLOCKED), int(LegFlags.NO_GROUND)
_OVERTEMP, _JAC_FAULT = int(LegFlags.OVERTEMP), int(LegFlags.JAC_FAULT)
_HOLD, _SWING, _STANCE, _RETRACT = int(LegPhase.HOLD), int(LegPhase.SWING), int(LegPhase.STANCE), int(LegPhase.RETRACT)
_NONE = int(MmcError.NONE)
_URGENCY = [int(e) for e in (MmcError.NO_GROUND, MmcError.LCP_OUT_OF_ORDER, MmcError.JAC_OUT_OF_ORDER,
                             MmcError.LEG_DRIVE_FAILED, MmcError.LEG_DRIVE_BLOCKED)]
_OUT_OF_ORDER = int(OrderStatus.OUT_OF_ORDER)


class MmcDebug(TypedDict):
    """MMC.debug_metrics(): metrics.json `nodes.MMC` (sim2d.metrics checks expectations on it at load)."""
    error: str                      # MmcError name
    error_leg: int
    errors: dict[str, str]          # leg -> MmcError name
    gait: str
    direction: str
    legs: int
    lost_legs: list[int]
    five_legged: bool
    gait_switches: int
    commands: dict[str, int]
    gaits_used: list[str]
    walked_s: dict[str, float]
    pits: int
    pause_s: float
    overtemp_legs: list[int]


class MMC(PostMaster, Runtime, MmcSkeleton):
    def start(self) -> None:
        g = self.cfg.geometry
        # the LCPs on the leg bus, by leg number (spec nodes: leg)
        self.lcps = {NODES[a].leg: a for a in slaves_of(self.master_bus) if NODES[a].role == "LCP"}
        self.gait = Gait(g)
        self.errors: dict[int, int] = {}          # leg -> MMC_ERROR
        self.dead: set[int] = set()               # legs whose LCP does not answer
        self.no_ground: set[int] = set()
        self.hot: set[int] = set()
        self.misses: dict[int, int] = {}
        self.sent: dict[int, tuple] = {}
        self.sent_at: dict[int, float] = {}
        self.poll_i = 0
        self.ready = False
        self.commands: dict[str, int] = {}
        self.gaits_used: set[str] = set()
        self.walked_s: dict[str, float] = {}
        self.pits = 0
        self.high_until = 0.0
        self.run_post(self.post_done)
        self.every(T.MMC_CONTROL_S, self.tick)

    @property
    def error(self) -> int:
        return self._worst()[1]

    @property
    def error_leg(self) -> int:
        return self._worst()[0]

    def _worst(self) -> tuple[int, int]:
        """(leg, error) of the most urgent error, (0, NONE) without one."""
        best = (0, _NONE)
        for leg in sorted(self.errors):
            e = self.errors[leg]
            if best[1] == _NONE or _URGENCY.index(e) < _URGENCY.index(best[1]):
                best = (leg, e)
        return best

    def post_done(self, missing: list[int]) -> None:
        for leg, lcp in self.lcps.items():
            if lcp in missing:
                self.lose(leg, int(MmcError.LCP_OUT_OF_ORDER), dead=True)
            elif any(a in missing for a in behind(lcp)):
                self.lose(leg, int(MmcError.JAC_OUT_OF_ORDER))
        self.ready = True

    def lose(self, leg: int, error: int, dead: bool = False) -> None:
        """seed 6.3: a leg is out (LCP or JAC out of order): walk on the other five."""
        self.errors[leg] = error
        if dead:
            self.dead.add(leg)
        if leg in self.gait.legs:
            self.gait.drop_leg(leg)
            self.hw.note("five_legged_gait", leg=leg)

    # --- commands ---------------------------------------------------------------------------------
    def on_move_relayed(self, src: int, msg: M.MoveRelayed) -> None:
        self.hw.note("move", mov_cmd=msg.mov_cmd)
        try:
            name = MovCmd(msg.mov_cmd).name
        except ValueError:
            return                                   # Mov_Cmd 10..15: not defined by seed 3.2.3
        self.commands[name] = self.commands.get(name, 0) + 1
        self.gait.set_command(msg.mov_cmd)

    # --- the gait clock -------------------------------------------------------------------------------
    def leg_target(self, leg: int) -> M.LegTarget:
        """The leg's current segment as a LEG_TARGET: end point relative to the hip, time left."""
        g = self.cfg.geometry
        hx, hy = g.hip(leg)
        if leg not in self.gait.legs:                # lost, its LCP alive: held lifted and tucked in, out of the way
            nx, ny = g.neutral_foot(leg)
            y = ny - g.side(leg) * T.MMC_LOST_LEG_TUCK_M
            return M.LegTarget(phase=_RETRACT, x=_MM.raw((nx - hx) * 1000), y=_MM.raw((y - hy) * 1000),
                               z=_MM.raw(T.MMC_LOST_LEG_LIFT_M * 1000), duration=_MS.raw(g.half_cycle * 1000))
        swing, (x, y), lift, left = self.gait.segment(leg)
        if swing:
            phase = _SWING
        elif left > 0:
            phase = _STANCE
        else:
            phase = _HOLD
        return M.LegTarget(phase=phase, x=_MM.raw((x - hx) * 1000), y=_MM.raw((y - hy) * 1000),
                           z=_MM.raw(lift * 1000), duration=_MS.raw(left / self.gait.scale * 1000))

    def tick(self) -> None:
        if not self.ready:
            return
        t = self.now
        if t > self.high_until:
            self.gait.swing_lift = self.cfg.geometry.lift
        self.gait.advance(T.MMC_CONTROL_S)
        if self.gait.command != STOP and not self.gait.paused:
            d = MovCmd(self.gait.command).name
            self.walked_s[d] = self.walked_s.get(d, 0.0) + T.MMC_CONTROL_S
            self.gaits_used.add("FIVE_LEGGED" if self.gait.lost else MovCmd(self.gait.gait).name)
        refresh = self.net.protocol.setpoint_refresh_s
        for leg, lcp in self.lcps.items():
            if leg in self.dead:
                continue
            msg = self.leg_target(leg)
            key = (msg.phase, msg.x, msg.y, msg.z)
            if self.sent.get(leg) == key and t - self.sent_at[leg] < refresh - 1e-9:
                continue
            self.sent[leg], self.sent_at[leg] = key, t
            self.request(lcp, msg)
        if t >= getattr(self, "next_poll", 0.0):
            self.next_poll = t + T.MMC_POLL_S
            legs = [leg for leg in sorted(self.lcps) if leg not in self.dead]
            missed = [leg for leg in legs if self.misses.get(leg, 0)]
            if missed:
                leg = missed[0]                      # a leg that missed its last poll is asked again first
            elif legs:
                leg = legs[self.poll_i % len(legs)]
                self.poll_i += 1
            if legs:
                self.request(self.lcps[leg], M.LegPoll(), (M.LegReport,), lambda s, r, leg=leg: self.report(leg, r),
                             lambda leg=leg: self.no_answer(leg))

    # --- leg reports -----------------------------------------------------------------------------------
    def no_answer(self, leg: int) -> None:
        """seed 3.2.4: an LCP that stops answering is out of order."""
        self.misses[leg] = self.misses.get(leg, 0) + 1
        if self.misses[leg] >= T.MMC_LEG_TIMEOUTS and leg not in self.dead:
            self.lose(leg, int(MmcError.LCP_OUT_OF_ORDER), dead=True)

    def report(self, leg: int, r: M.LegReport) -> None:
        self.misses[leg] = 0
        err = self.errors.get(leg, _NONE)
        if r.flags & _JAC_FAULT:
            if err != int(MmcError.JAC_OUT_OF_ORDER) and leg in self.gait.legs:
                self.lose(leg, int(MmcError.JAC_OUT_OF_ORDER))
            return
        if leg not in self.gait.legs:
            return
        # seed 1.2.2: a foot finds no ground: stop now (edge: the next MOVE is obeyed)
        if r.flags & _NO_GROUND:
            if leg not in self.no_ground:
                self.no_ground.add(leg)
                self.pits += 1
                self.hw.note("pit", leg=leg)
                self.gait.set_command(STOP)
            self.errors[leg] = int(MmcError.NO_GROUND)
            return
        self.no_ground.discard(leg)
        # seed 6.1: a blocked leg; still blocked after the LCP's retry (it says OUT_OF_ORDER): failed
        if r.flags & _BLOCKED:
            # an obstacle under the legs: every leg steps high for a while (seed 1.2.1 step limit)
            self.high_until = self.now + T.MMC_HIGH_STEP_S
            self.gait.swing_lift = self.cfg.geometry.step_limit + T.LCP_RETRY_CLEARANCE_M
            if err != int(MmcError.LEG_DRIVE_FAILED):
                self.errors[leg] = int(MmcError.LEG_DRIVE_BLOCKED)
                self.request(self.lcps[leg], M.StatusReq(), (M.StatusAckOrder,),
                             lambda s, a, leg=leg: self.leg_status(leg, a))
        elif err != _NONE:
            del self.errors[leg]
        # servo over-temperature anywhere: the whole gait slows down (the legs stay in step)
        if r.flags & _OVERTEMP:
            self.hot.add(leg)
        else:
            self.hot.discard(leg)
        self.gait.set_scale(T.MMC_OVERTEMP_SCALE if self.hot else 1.0)

    def leg_status(self, leg: int, ack: M.StatusAckOrder) -> None:
        if ack.status == _OUT_OF_ORDER and self.errors.get(leg) == int(MmcError.LEG_DRIVE_BLOCKED):
            self.errors[leg] = int(MmcError.LEG_DRIVE_FAILED)

    def status_ack(self) -> M.StatusAckMmc:
        """seed 3.2.4: gait, direction and the most urgent error with the leg it refers to."""
        leg, err = self._worst()
        return M.StatusAckMmc(gait=int(GaitCode(self.gait.gait)), direction=int(Direction(self.gait.command)),
                              leg=leg, error=err)

    def debug_metrics(self) -> MmcDebug:
        """Debug port: what the MMC did (scenario expectations read these)."""
        leg, err = self._worst()
        return {
            "error": MmcError(err).name, "error_leg": leg, "errors": {str(k): MmcError(v).name for k, v in sorted(self.errors.items())},
            "gait": MovCmd(self.gait.gait).name, "direction": MovCmd(self.gait.command).name,
            "legs": len(self.gait.legs), "lost_legs": sorted(self.gait.lost),
            "five_legged": bool(self.gait.lost), "gait_switches": self.gait.gait_switches,
            "commands": dict(sorted(self.commands.items())), "gaits_used": sorted(self.gaits_used),
            "walked_s": {k: round(v, 2) for k, v in sorted(self.walked_s.items())},
            "pits": self.pits, "pause_s": round(self.gait.pause_s, 2), "overtemp_legs": sorted(self.hot),
        }
