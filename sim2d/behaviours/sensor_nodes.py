"""The sensor controllers on the SPU's bus (seed 3.2.11-3.2.17).

Each answers XMIT_DATA with its own XMIT_DATA_<role> frame, reading the
simulated physics through sim2d.sensors only when asked (or, for the
scanning USRC and the TPSC, on its own clock).
"""
from __future__ import annotations

from sim2d.behaviours.base import NodeProcess

SPREAD_US_RAW = 8        # CHOICE: 3 sonar readings further apart than ~30 cm are suspect (3.2.11)
SPREAD_IR_RAW = 40       # CHOICE: 3 IR readings further apart than ~1.5 cm are suspect (3.2.13)
HEAD_STEP_S = 0.005      # CHOICE: time to turn the head by 1 degree
IR_NEAR_RAW = 150        # CHOICE: about 6 cm, an obstacle ahead (stimulus for the latency metric)


def _reliable(readings: list[int], spread: int) -> bool:
    return max(readings) - min(readings) <= spread


class RangeSensor(NodeProcess):
    """USRC and IRRC: three readings averaged; two bad sets in a row -> UNRELIABLE (3.2.11, 3.2.13, 6.2)."""

    def start(self) -> None:
        self.status_codes = self.ctx.spec.enums["RANGE_STATUS"].values
        self.status = self.status_codes["IN_ORDER"]
        self.bad_sets = 0

    def judge(self, sets_ok: bool) -> None:
        self.bad_sets = 0 if sets_ok else self.bad_sets + 1
        if self.bad_sets >= 2:
            self.status = self.status_codes["UNRELIABLE"]


class USRC(RangeSensor):
    def start(self) -> None:
        super().start()
        self.head = 0
        self.latest = (255, 0)
        self.free_run = False

    def on_free_run(self, bus: str, src: int, f: dict) -> None:
        if not self.free_run:
            self.free_run = True
            self.after(HEAD_STEP_S, self.scan_step)

    def measure(self) -> float:
        readings, tof = [], 0.0
        for attempt in range(2):
            readings = []
            for _ in range(3):
                raw, dt = self.ctx.sensors.usrc_ping(self.head, self.now)
                readings.append(raw)
                tof += dt
            ok = _reliable(readings, SPREAD_US_RAW)
            if ok:
                break
        self.judge(ok)
        self.latest = (round(sum(readings) / 3), self.head)
        return tof

    def scan_step(self) -> None:
        tof = self.measure()
        self.head = (self.head + 1) % 360          # seed 3.2.11: 1 degree steps
        self.after(tof + HEAD_STEP_S, self.scan_step)

    def on_head_set_abs(self, bus: str, src: int, f: dict) -> None:
        self.head = f["angle"] % 360

    def on_head_set_rel(self, bus: str, src: int, f: dict) -> None:
        self.head = (self.head + f["angle"]) % 360

    def on_head_step(self, bus: str, src: int, f: dict) -> None:
        self.head = (self.head + 1) % 360

    def on_do_measure(self, bus: str, src: int, f: dict) -> None:
        self.measure()

    def on_xmit_data(self, bus: str, src: int, f: dict) -> None:
        self.reply(bus, src, "XMIT_DATA_USRC", distance=self.latest[0], angle=self.latest[1])


class IRRC(RangeSensor):
    near = False

    def on_xmit_data(self, bus: str, src: int, f: dict) -> None:
        sets = []
        for attempt in range(2):
            sets = [self.ctx.sensors.irrc() for _ in range(3)]
            ok = all(_reliable([s[i] for s in sets], SPREAD_IR_RAW) for i in range(3))
            if ok:
                break
        self.judge(ok)
        left, center, right = (round(sum(s[i] for s in sets) / 3) for i in range(3))
        near = min(left, center, right) < IR_NEAR_RAW
        if near and not self.near:
            self.ctx.stimulus(self.now, "ir")      # a new object close ahead (latency metric, 5.2)
        self.near = near
        self.reply(bus, src, "XMIT_DATA_IRRC", left=left, center=center, right=right)


class TPSC(NodeProcess):
    """seed 3.2.12: the TPSC always initiates: DATA_RDY when a whisker touches."""

    tick_period = 0.02   # CHOICE: switch debounce / scan period

    def start(self) -> None:
        self.contact = 0
        self.latched = 0

    def tick(self, t: float) -> None:
        c = self.ctx.sensors.tpsc(t)
        if c and c != self.contact:
            self.latched = c
            self.ctx.stimulus(t, "whisker")
            self.slave_send(self.node.bus, self.ctx.spec.node(self.ctx.master_of(self.node.bus)).address, "DATA_RDY")
        self.contact = c

    def on_xmit_data(self, bus: str, src: int, f: dict) -> None:
        self.reply(bus, src, "XMIT_DATA_TPSC", contact=self.latched or self.contact)
        self.latched = 0


class ISC(NodeProcess):
    def on_xmit_data(self, bus: str, src: int, f: dict) -> None:
        lon, tr = self.ctx.sensors.isc()
        self.reply(bus, src, "XMIT_DATA_ISC", longitudinal=lon, transverse=tr)


class TSC(NodeProcess):
    def start(self) -> None:
        self.channel = 0

    def on_xmit_data(self, bus: str, src: int, f: dict) -> None:
        values = self.ctx.sensors.tsc()
        ch = self.channel
        self.channel = (ch + 1) % len(values)
        self.reply(bus, src, "XMIT_DATA_TSC", channel=ch, temperature=values[ch])


class LSC(NodeProcess):
    def on_xmit_data(self, bus: str, src: int, f: dict) -> None:
        readings = [self.ctx.sensors.lsc() for _ in range(3)]     # seed 3.2.16: mean of the last three
        self.reply(bus, src, "XMIT_DATA_LSC", brightness=round(sum(readings) / 3))


class PSC(NodeProcess):
    def on_xmit_data(self, bus: str, src: int, f: dict) -> None:
        readings = [self.ctx.sensors.psc() for _ in range(3)]     # seed 3.2.17: mean of the last three
        self.reply(bus, src, "XMIT_DATA_PSC", voltage=round(sum(readings) / 3))
