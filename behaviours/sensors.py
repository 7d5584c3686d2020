"""The sensor controllers on the SPU's bus (seed 3.2.11-3.2.17).

Each answers XMIT_DATA with its own XMIT_DATA_<role> frame, reading its
sensor through the hardware interface only when asked (or, for the scanning
USRC and the TPSC, on its own clock) and quantising the physical reading
into the spec's encoding (behaviours.units).
"""
from __future__ import annotations

from arachnae_proto import messages as M
from arachnae_proto.enums import RangeStatus, TpscContact
from arachnae_proto.network import ADDRESS_OF, BUSES, NODES
from arachnae_proto.skeletons.irrc import IrrcSkeleton
from arachnae_proto.skeletons.isc import IscSkeleton
from arachnae_proto.skeletons.lsc import LscSkeleton
from arachnae_proto.skeletons.psc import PscSkeleton
from arachnae_proto.skeletons.tpsc import TpscSkeleton
from arachnae_proto.skeletons.tsc import TscSkeleton
from arachnae_proto.skeletons.usrc import UsrcSkeleton

from behaviours import tuning as T
from behaviours.runtime import Runtime
from behaviours.units import quantizer

_US_M = quantizer(M.XmitDataUsrc, "distance")
_IR_CM = quantizer(M.XmitDataIrrc, "center")
_ISC_DEG = quantizer(M.XmitDataIsc, "longitudinal")
_TSC_C = quantizer(M.XmitDataTsc, "temperature")
_LSC_LX = quantizer(M.XmitDataLsc, "brightness")
_PSC_V = quantizer(M.XmitDataPsc, "voltage")
_IN_ORDER, _UNRELIABLE = int(RangeStatus.IN_ORDER), int(RangeStatus.UNRELIABLE)
_LEFT, _RIGHT, _BOTH = int(TpscContact.OBJ_LEFT), int(TpscContact.OBJ_RIGHT), int(TpscContact.OBJ_BOTH)


def _reliable(readings: list[int], spread: int) -> bool:
    return max(readings) - min(readings) <= spread


def _mean(values: list[int]) -> int:
    return round(sum(values) / len(values))


class _RangeSensor(Runtime):
    """USRC and IRRC: three readings averaged; two bad sets in a row -> UNRELIABLE (3.2.11, 3.2.13, 6.2)."""

    status = _IN_ORDER
    bad_sets = 0

    def judge(self, sets_ok: bool) -> None:
        self.bad_sets = 0 if sets_ok else self.bad_sets + 1
        if self.bad_sets >= 2:
            self.status = _UNRELIABLE

    def status_ack(self) -> M.StatusAckRange:
        return M.StatusAckRange(status=self.status)


class USRC(_RangeSensor, UsrcSkeleton):
    def start(self) -> None:
        self.head = 0
        self.latest = (_US_M.hi, 0)
        self.free_run = False

    def on_free_run(self, src: int, msg: M.FreeRun) -> None:
        if not self.free_run:
            self.free_run = True
            self.hw.after(T.USRC_HEAD_STEP_S, self.scan_step)

    def measure(self) -> float:
        """Three pings averaged, three more if they spread too far (3.2.11); returns the time taken."""
        readings: list[int] = []
        tof, ok = 0.0, False
        for _attempt in range(2):
            readings = []
            for _ in range(3):
                metres, dt = self.hw.sonar_ping(self.head)
                readings.append(_US_M.hi if metres is None else _US_M.raw(metres))
                tof += dt
            ok = _reliable(readings, T.USRC_SPREAD_RAW)
            if ok:
                break
        self.judge(ok)
        self.latest = (_mean(readings), self.head)
        return tof

    def scan_step(self) -> None:
        tof = self.measure()
        self.head = (self.head + 1) % 360          # seed 3.2.11: 1 degree steps
        self.hw.after(tof + T.USRC_HEAD_STEP_S, self.scan_step)

    def on_head_set_abs(self, src: int, msg: M.HeadSetAbs) -> None:
        self.head = msg.angle % 360

    def on_head_set_rel(self, src: int, msg: M.HeadSetRel) -> None:
        self.head = (self.head + msg.angle) % 360

    def on_head_step(self, src: int, msg: M.HeadStep) -> None:
        self.head = (self.head + 1) % 360

    def on_do_measure(self, src: int, msg: M.DoMeasure) -> None:
        self.measure()

    def on_xmit_data(self, src: int, msg: M.XmitData) -> None:
        self.send(src, M.XmitDataUsrc(distance=self.latest[0], angle=self.latest[1]))


class IRRC(_RangeSensor, IrrcSkeleton):
    near = False

    def read(self) -> tuple[int, ...]:
        return tuple(_IR_CM.hi if m is None else _IR_CM.raw(m * 100) for m in self.hw.ir_ranges())

    def on_xmit_data(self, src: int, msg: M.XmitData) -> None:
        sets: list[tuple[int, ...]] = []
        ok = False
        for _attempt in range(2):
            sets = [self.read() for _ in range(3)]
            ok = all(_reliable([s[i] for s in sets], T.IRRC_SPREAD_RAW) for i in range(3))
            if ok:
                break
        self.judge(ok)
        left, center, right = (_mean([s[i] for s in sets]) for i in range(3))
        near = _IR_CM.phys(min(left, center, right)) / 100 < T.IRRC_NEAR_M
        if near and not self.near:
            self.hw.note("stimulus", kind="ir")      # a new object close ahead (latency metric, 5.2)
        self.near = near
        self.send(src, M.XmitDataIrrc(left=left, center=center, right=right))


class TPSC(Runtime, TpscSkeleton):
    """seed 3.2.12: the TPSC always initiates: DATA_RDY when a whisker touches."""

    def start(self) -> None:
        self.contact = 0
        self.latched = 0
        self.master = ADDRESS_OF[BUSES[NODES[self.address][2]][0]]   # the master of its bus
        self.every(T.TPSC_SCAN_S, self.scan)

    def scan(self) -> None:
        left, right = self.hw.whiskers()
        c = _BOTH if left and right else _LEFT if left else _RIGHT if right else 0
        if c and c != self.contact:
            self.latched = c
            self.hw.note("stimulus", kind="whisker")
            self.slave_send(self.master, M.DataRdy())
        self.contact = c

    def on_xmit_data(self, src: int, msg: M.XmitData) -> None:
        self.send(src, M.XmitDataTpsc(contact=self.latched or self.contact))
        self.latched = 0


class ISC(Runtime, IscSkeleton):
    def on_xmit_data(self, src: int, msg: M.XmitData) -> None:
        lon, tr = self.hw.inclination()
        self.send(src, M.XmitDataIsc(longitudinal=_ISC_DEG.raw(lon), transverse=_ISC_DEG.raw(tr)))


class TSC(Runtime, TscSkeleton):
    def start(self) -> None:
        self.channel = 0

    def on_xmit_data(self, src: int, msg: M.XmitData) -> None:
        values = self.hw.temperatures()
        ch = self.channel
        self.channel = (ch + 1) % len(values)
        self.send(src, M.XmitDataTsc(channel=ch, temperature=_TSC_C.raw(values[ch])))


class LSC(Runtime, LscSkeleton):
    def on_xmit_data(self, src: int, msg: M.XmitData) -> None:
        readings = [_LSC_LX.raw(self.hw.light()) for _ in range(3)]     # seed 3.2.16: mean of the last three
        self.send(src, M.XmitDataLsc(brightness=_mean(readings)))


class PSC(Runtime, PscSkeleton):
    def on_xmit_data(self, src: int, msg: M.XmitData) -> None:
        readings = [_PSC_V.raw(self.hw.battery()) for _ in range(3)]    # seed 3.2.17: mean of the last three
        self.send(src, M.XmitDataPsc(voltage=_mean(readings)))
