"""MMC (seed 3.2.4): turns MOVE into a gait and sends each leg its next foot target.

The gait generator (sim2d.gait) runs on the MMC's clock; whenever a leg
starts a stance or swing segment the MMC sends that leg's LCP a LEG_TARGET
(end point relative to the hip, phase, duration). It polls the legs for
LEG_REPORT: a blocked leg sets error LEG_DRIVE_BLOCKED (seed 6.1), a foot
finding no ground at touchdown stops the robot (pit, seed 1.2.2).
"""
from __future__ import annotations

from sim2d.behaviours.base import Master, Request
from sim2d.gait import STOP, WAVE, Gait

CONTROL_PERIOD = 0.02    # CHOICE: MMC gait clock
POLL_PERIOD = 0.1        # CHOICE: one LEG_POLL every 100 ms, legs in turn


class MMC(Master):
    tick_period = CONTROL_PERIOD

    def start(self) -> None:
        p = self.ctx.params
        self.lcps = {n.leg: n for n in self.ctx.spec.role_nodes("LCP")}
        self.gait = Gait(p)
        self.legs_ok = set(self.lcps)
        self.sent: dict[int, tuple] = {}
        self.error, self.error_leg = 0, 0
        self.poll_i = 0
        self.next_poll = 0.0
        self.ready = False
        self.run_post(self.post_done)

    def post_done(self, missing: list[int]) -> None:
        spec = self.ctx.spec
        for leg, lcp in self.lcps.items():
            unit = [lcp.address] + [n.address for n in spec.role_nodes("JAC") if n.leg == leg]
            if any(a in missing for a in unit):
                self.legs_ok.discard(leg)
        if len(self.legs_ok) < len(self.lcps):
            self.gait.set_command(WAVE)   # CHOICE: with a leg missing only the wave gait keeps >= 4 feet down
        self.ready = True

    def on_move_relayed(self, bus: str, src: int, f: dict) -> None:
        self.ctx.move_received(self.now, f["mov_cmd"])
        gaits = self.ctx.spec.enums["GAIT"].values.values()
        if f["mov_cmd"] in gaits and len(self.legs_ok) < len(self.lcps):
            return
        self.gait.set_command(f["mov_cmd"])

    def tick(self, t: float) -> None:
        if not self.ready:
            return
        p = self.ctx.params
        phase_codes = self.ctx.spec.enums["LEG_PHASE"].values
        self.gait.advance(CONTROL_PERIOD)
        for leg in self.legs_ok:
            pl = self.gait.plans[leg]
            key = (pl.swing, pl.end, pl.active, round(pl.lift, 4), pl.s0)
            if self.sent.get(leg) == key:
                continue
            self.sent[leg] = key
            hx, hy = p.hip(leg)
            u_len = (1 - self.gait.duty) if pl.swing else self.gait.duty
            duration = 0 if not pl.active else int(round(u_len * (1 - pl.s0) * self.gait.cycle * 1000))
            phase = phase_codes["HOLD"] if not pl.active else phase_codes["SWING" if pl.swing else "STANCE"]
            self.request("leg", Request(self.lcps[leg].address, "LEG_TARGET", {
                "phase": phase, "x": round((pl.end[0] - hx) * 10000), "y": round((pl.end[1] - hy) * 10000),
                "z": round(pl.lift * 10000) if pl.swing else 0, "duration": duration}))
        if t >= self.next_poll and self.legs_ok:
            self.next_poll = t + POLL_PERIOD
            legs = sorted(self.legs_ok)
            leg = legs[self.poll_i % len(legs)]
            self.poll_i += 1
            self.request("leg", Request(self.lcps[leg].address, "LEG_POLL", {}, ("LEG_REPORT",),
                                        lambda s, n, f, leg=leg: self.report(leg, f)))

    def report(self, leg: int, f: dict) -> None:
        bits = self.ctx.spec.flags["LEG_FLAGS"].bits
        errors = self.ctx.spec.enums["MMC_ERROR"].values
        if f["flags"] & bits["BLOCKED"]:
            self.error, self.error_leg = errors["LEG_DRIVE_BLOCKED"], leg
        if f["flags"] & bits["NO_GROUND"] and self.gait.command != STOP:
            self.ctx.event("pit", self.now, leg)
            self.gait.set_command(STOP)

    def on_status_req(self, bus: str, src: int, f: dict) -> None:
        self.reply(bus, src, "STATUS_ACK_MMC", gait=self.gait.gait, direction=self.gait.command,
                   leg=self.error_leg, error=self.error)
