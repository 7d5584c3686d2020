"""MMC (seed 3.2.4): turns MOVE into a gait and sends each leg its next foot target.

The gait generator (behaviours.gait) runs on the MMC's clock; whenever a leg
starts a stance or swing segment the MMC sends that leg's LCP a LEG_TARGET
(end point relative to the hip, phase, duration), and repeats an unchanged
target every `setpoint_refresh_ms` (spec protocol: targets are not
acknowledged) with the time left. It polls the legs for LEG_REPORT: a
blocked leg sets error LEG_DRIVE_BLOCKED (seed 6.1), a foot finding no
ground at touchdown stops the robot (pit, seed 1.2.2).
"""
from __future__ import annotations

from arachnae_proto import messages as M
from arachnae_proto.enums import Gait as GaitCode, LegFlags, LegPhase, MmcError
from arachnae_proto.network import NODES
from arachnae_proto.skeletons.mmc import MmcSkeleton

from behaviours import tuning as T
from behaviours.gait import STOP, WAVE, Gait
from behaviours.post import PostMaster, behind
from behaviours.runtime import Runtime, slaves_of
from behaviours.units import quantizer

_MM = quantizer(M.LegTarget, "x")          # mm on the wire (deci-mm raw)
_MS = quantizer(M.LegTarget, "duration")
_GAITS = frozenset(int(g) for g in GaitCode)
_BLOCKED, _NO_GROUND = int(LegFlags.BLOCKED), int(LegFlags.NO_GROUND)
_HOLD, _SWING, _STANCE = int(LegPhase.HOLD), int(LegPhase.SWING), int(LegPhase.STANCE)


class MMC(PostMaster, Runtime, MmcSkeleton):
    def start(self) -> None:
        g = self.cfg.geometry
        # the LCPs on the leg bus, by leg number (spec nodes: leg)
        self.lcps = {self.net.leg_of(a): a for a in slaves_of(self.master_bus) if NODES[a][1] == "LCP"}
        self.gait = Gait(g)
        self.legs_ok = set(self.lcps)
        self.sent: dict[int, tuple] = {}
        self.sent_at: dict[int, float] = {}
        self.error, self.error_leg = int(MmcError.NONE), 0
        self.poll_i = 0
        self.next_poll = 0.0
        self.ready = False
        self.run_post(self.post_done)
        self.every(T.MMC_CONTROL_S, self.tick)

    def post_done(self, missing: list[int]) -> None:
        for leg, lcp in self.lcps.items():
            if lcp in missing or any(a in missing for a in behind(lcp)):
                self.legs_ok.discard(leg)
        if len(self.legs_ok) < len(self.lcps):
            self.gait.set_command(WAVE)   # CHOICE: with a leg missing only the wave gait keeps >= 4 feet down
        self.ready = True

    def on_move_relayed(self, src: int, msg: M.MoveRelayed) -> None:
        self.hw.note("move", mov_cmd=msg.mov_cmd)
        if msg.mov_cmd in _GAITS and len(self.legs_ok) < len(self.lcps):
            return
        self.gait.set_command(msg.mov_cmd)

    def leg_target(self, leg: int) -> M.LegTarget:
        """The leg's current segment as a LEG_TARGET: end point relative to the hip, time left."""
        g, gait = self.cfg.geometry, self.gait
        pl = gait.plans[leg]
        hx, hy = g.hip(leg)
        if pl.active:
            swing, s = gait._local(leg)
            u_len = (1 - gait.duty) if pl.swing else gait.duty
            left = u_len * (1 - s) * gait.cycle if swing == pl.swing else 0.0
            duration = _MS.raw(left * 1000)
            phase = _SWING if pl.swing else _STANCE
        else:
            duration, phase = 0, _HOLD
        return M.LegTarget(phase=phase, x=_MM.raw((pl.end[0] - hx) * 1000), y=_MM.raw((pl.end[1] - hy) * 1000),
                           z=_MM.raw(pl.lift * 1000) if pl.swing else 0, duration=duration)

    def tick(self) -> None:
        if not self.ready:
            return
        t = self.now
        self.gait.advance(T.MMC_CONTROL_S)
        refresh = self.net.protocol.setpoint_refresh_s
        for leg in self.legs_ok:
            pl = self.gait.plans[leg]
            key = (pl.swing, pl.end, pl.active, round(pl.lift, 4), pl.s0)
            if self.sent.get(leg) == key and t - self.sent_at[leg] < refresh - 1e-9:
                continue
            self.sent[leg], self.sent_at[leg] = key, t
            self.request(self.lcps[leg], self.leg_target(leg))
        if t >= self.next_poll and self.legs_ok:
            self.next_poll = t + T.MMC_POLL_S
            legs = sorted(self.legs_ok)
            leg = legs[self.poll_i % len(legs)]
            self.poll_i += 1
            self.request(self.lcps[leg], M.LegPoll(), (M.LegReport,), lambda s, r, leg=leg: self.report(leg, r))

    def report(self, leg: int, r: M.LegReport) -> None:
        if r.flags & _BLOCKED:
            self.error, self.error_leg = int(MmcError.LEG_DRIVE_BLOCKED), leg
        if r.flags & _NO_GROUND and self.gait.command != STOP:
            self.hw.note("pit", leg=leg)
            self.gait.set_command(STOP)

    def status_ack(self) -> M.StatusAckMmc:
        """seed 3.2.4: gait, direction and the error code with the leg it refers to."""
        return M.StatusAckMmc(gait=self.gait.gait, direction=self.gait.command, leg=self.error_leg, error=self.error)
