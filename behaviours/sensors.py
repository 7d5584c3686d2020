"""The sensor controllers on the SPU's bus (seed 3.2.11-3.2.17).

Each answers XMIT_DATA with its own XMIT_DATA_<role> frame and quantises
the physical reading into the spec's encoding (behaviours.units). The
range sensors take three readings per measurement, three more when they
spread too far, and declare themselves UNRELIABLE when those spread too
(3.2.11, 3.2.13). The IRRC, ISC, TSC, LSC and PSC measure on their own
clock, so they can check the limit the SPU set with SET_ALARM at every
measurement and raise DATA_RDY on their own when it is crossed; the USRC
scans in FREE_RUN and announces each sector's nearest echo with DATA_RDY.

CHOICE (the seed is silent): a range sensor stays UNRELIABLE until it is
initialised again (INIT); an unreliable measurement never replaces the last
reliable value it reports.
"""
from __future__ import annotations

from collections import deque
from typing import Callable, TypedDict

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
from behaviours.units import Quantizer, quantizer

_US_M = quantizer(M.XmitDataUsrc, "distance")
_IR_CM = quantizer(M.XmitDataIrrc, "center")
_ISC_DEG = quantizer(M.XmitDataIsc, "longitudinal")
_TSC_C = quantizer(M.XmitDataTsc, "temperature")
_LSC_LX = quantizer(M.XmitDataLsc, "brightness")
_PSC_V = quantizer(M.XmitDataPsc, "voltage")
_IN_ORDER, _UNRELIABLE = int(RangeStatus.IN_ORDER), int(RangeStatus.UNRELIABLE)
_LEFT, _RIGHT, _BOTH = int(TpscContact.OBJ_LEFT), int(TpscContact.OBJ_RIGHT), int(TpscContact.OBJ_BOTH)

BELOW, ABOVE, BEYOND = "below", "above", "beyond"


def _mean(values: list[int]) -> int:
    return round(sum(values) / len(values))


def limit_in(data: Quantizer, alarm: type[M.Message], raw_limit: int) -> int:
    """A SET_ALARM limit in the data field's raw steps (through physical units: the encodings may differ)."""
    (limit,) = [a.limit for a in M.ALARM_THRESHOLDS.values() if a.message is alarm]   # spec compared_with
    return data.raw(quantizer(alarm, limit).phys(raw_limit))


class AlarmLimit:
    """One SET_ALARM limit: fires once when the value crosses it, re-arms once it is back by `rearm` steps."""

    __slots__ = ("limit", "sense", "rearm", "armed")

    def __init__(self, limit: int, sense: str, rearm: int) -> None:
        self.limit, self.sense, self.rearm, self.armed = limit, sense, rearm, True

    def beyond(self, v: int) -> bool:
        if self.sense == BELOW:
            return v < self.limit
        if self.sense == ABOVE:
            return v > self.limit
        return abs(v) > abs(self.limit)        # CHOICE (3.2.14): inclination beyond the limit either way

    def check(self, v: int) -> bool:
        """True on the crossing edge only (seed: the sensor reports on its own when the limit is crossed)."""
        if self.armed and self.beyond(v):
            self.armed = False
            return True
        if not self.armed:
            back = {BELOW: v >= self.limit + self.rearm, ABOVE: v <= self.limit - self.rearm}.get(
                self.sense, abs(v) <= abs(self.limit) - self.rearm)
            self.armed = back
        return False


class SensorDebug(TypedDict):
    """_Sensor.debug_metrics(): metrics.json `nodes.<sensor>` (sim2d.metrics checks expectations on it at load)."""
    alarms: int


class RangeSensorDebug(SensorDebug):
    status: str                     # RangeStatus name
    measurements: int
    second_sets: int


class PscDebug(SensorDebug):
    mean_v: float | None
    mean_min_v: float | None
    level_min_v: float | None


class _Sensor(Runtime):
    """What the sensor controllers share: the SPU as master, DATA_RDY announcements, SET_ALARM limits."""

    def start(self) -> None:
        self.master = ADDRESS_OF[BUSES[NODES[self.address].bus].master]   # the master of its bus
        self.alarms: dict[int, AlarmLimit] = {}
        self.announced_at: float | None = None
        self.alarm_count = 0

    def announce(self, force: bool = False) -> None:
        """DATA_RDY to the SPU, once until it fetches the data (again after SENSOR_DATA_RDY_RETRY_S);
        `force`: now, whatever was announced (the simulator's worst-contention hook)."""
        if not force and self.announced_at is not None and self.now - self.announced_at < T.SENSOR_DATA_RDY_RETRY_S:
            return
        self.announced_at = self.now
        self.slave_send(self.master, M.DataRdy())

    def fetched(self) -> None:
        self.announced_at = None

    def set_alarm(self, channel: int, limit: int, sense: str) -> None:
        self.alarms[channel] = AlarmLimit(limit, sense, T.ALARM_REARM_RAW[self.ROLE])  # type: ignore[attr-defined]

    def check_alarms(self, values: dict[int, int]) -> list[int]:
        """The channels whose limit was crossed by this measurement; announced at once (seed 3.2.13-3.2.17)."""
        fired = [ch for ch, v in values.items() if ch in self.alarms and self.alarms[ch].check(v)]
        if fired:
            self.alarm_count += 1
            self.hw.note("sensor_alarm", node=self.name, channels=fired)  # type: ignore[attr-defined]
            self.announce()
        return fired

    def debug_metrics(self) -> SensorDebug:
        return {"alarms": self.alarm_count}


class _RangeSensor(_Sensor):
    """USRC and IRRC: the three-plus-three rule of seed 3.2.11 / 3.2.13 and their status."""

    def start(self) -> None:
        super().start()
        self.status = _IN_ORDER
        self.free_run = False
        self.measurements = 0
        self.second_sets = 0

    def three_plus_three(self, read: Callable[[], tuple[int, ...]], spread: int) -> tuple[int, ...] | None:
        """seed 3.2.11/3.2.13: three readings averaged; if they spread too far, three more; if those spread
        too far as well the sensor declares itself UNRELIABLE (None is returned)."""
        self.measurements += 1
        for attempt in range(2):
            sets = [read() for _ in range(3)]
            per_channel = list(zip(*sets))
            if all(max(c) - min(c) <= spread for c in per_channel):
                return tuple(_mean(list(c)) for c in per_channel)
            if attempt == 0:
                self.second_sets += 1
        self.declare(_UNRELIABLE)
        return None

    def declare(self, status: int) -> None:
        if status == self.status:
            return
        self.status = status
        self.hw.note("sensor_status", node=self.name, status=RangeStatus(status).name)  # type: ignore[attr-defined]
        if not self.free_run:
            self.announce()        # CHOICE: a status change is news for the SPU (it asks STATUS_REQ)

    def status_ack(self) -> M.StatusAckRange:
        return M.StatusAckRange(status=self.status)

    def reset(self) -> None:
        """INIT: initialised again by its master, the sensor trusts itself again (CHOICE)."""
        self.status = _IN_ORDER
        self.alarms.clear()

    def on_free_run(self, src: int, msg: M.FreeRun) -> None:
        self.free_run = True

    def debug_metrics(self) -> RangeSensorDebug:
        return {**super().debug_metrics(), "status": RangeStatus(self.status).name,
                "measurements": self.measurements, "second_sets": self.second_sets}


class USRC(_RangeSensor, UsrcSkeleton):
    """seed 3.2.11: the sonar head turns in 1 degree steps; FREE_RUN scans on and on."""

    def start(self) -> None:
        super().start()
        self.head = 0
        self.latest = (_US_M.hi, 0)
        self.sector: tuple[int, int] | None = None     # nearest echo of the sector being scanned
        self.ready: tuple[int, int] | None = None      # a finished sector, announced, not yet fetched
        self.scanning = False

    def on_free_run(self, src: int, msg: M.FreeRun) -> None:
        super().on_free_run(src, msg)
        if not self.scanning:
            self.scanning = True
            self.hw.after(T.USRC_HEAD_STEP_S, self.scan_step)

    def measure(self) -> float:
        """One measurement at the head's angle; returns the time the pings took."""
        tof = 0.0

        def ping() -> tuple[int]:
            nonlocal tof
            metres, dt = self.hw.sonar_ping(self.head)
            tof += dt
            return (_US_M.hi if metres is None else _US_M.raw(metres),)
        got = self.three_plus_three(ping, T.USRC_SPREAD_RAW)
        if got is not None:
            self.latest = (got[0], self.head)
        return tof

    def scan_step(self) -> None:
        tof = self.measure()
        if self.status == _IN_ORDER and self.latest[1] == self.head:
            if self.sector is None or self.latest[0] < self.sector[0]:
                self.sector = self.latest
        self.head = (self.head + 1) % 360          # seed 3.2.11: 1 degree steps
        if self.head % T.USRC_SECTOR_DEG == 0 and self.sector is not None:
            # FREE_RUN (spec): announce data with DATA_RDY; not while the sensor does not trust itself (6.2)
            self.ready, self.sector = self.sector, None
            if self.status == _IN_ORDER:
                self.announced_at = None
                self.announce()
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
        """The last sector's nearest echo once announced, else the last measured distance (3.2.11)."""
        distance, angle = self.ready or self.latest
        self.ready = None
        self.fetched()
        self.send(src, M.XmitDataUsrc(distance=distance, angle=angle))


class IRRC(_RangeSensor, IrrcSkeleton):
    """seed 3.2.13: three beams (left, centre, right), measured on its own clock."""

    near = False

    def start(self) -> None:
        super().start()
        self.latest = (_IR_CM.hi,) * 3
        self.every(T.IRRC_MEASURE_S, self.measure)

    def read(self) -> tuple[int, ...]:
        return tuple(_IR_CM.hi if m is None else _IR_CM.raw(m * 100) for m in self.hw.ir_ranges())

    def measure(self) -> None:
        got = self.three_plus_three(self.read, T.IRRC_SPREAD_RAW)
        if got is None:
            return
        self.latest = got
        near = _IR_CM.phys(min(got)) / 100 < T.IRRC_NEAR_M
        if near and not self.near:
            self.hw.note("stimulus", kind="ir")      # a new object close ahead (latency metric, 5.2)
        self.near = near
        if self.status == _IN_ORDER:
            self.check_alarms(dict(enumerate(got)))
        if self.free_run:
            self.announce()                          # FREE_RUN: announce data with DATA_RDY

    def on_do_measure(self, src: int, msg: M.DoMeasure) -> None:
        self.measure()

    def on_set_alarm_irrc(self, src: int, msg: M.SetAlarmIrrc) -> None:
        """seed 3.2.13: report on its own when an object comes closer than the limit (any beam)."""
        limit = limit_in(_IR_CM, M.SetAlarmIrrc, msg.limit)
        for beam in range(3):
            self.set_alarm(beam, limit, BELOW)

    def on_xmit_data(self, src: int, msg: M.XmitData) -> None:
        self.fetched()
        left, center, right = self.latest
        self.send(src, M.XmitDataIrrc(left=left, center=center, right=right))


class TPSC(Runtime, TpscSkeleton):
    """seed 3.2.12: the TPSC always initiates: DATA_RDY when a whisker touches."""

    def start(self) -> None:
        self.contact = 0
        self.latched = 0
        self.master = ADDRESS_OF[BUSES[NODES[self.address].bus].master]   # the master of its bus
        reflex = self.net.reflex_from(self.address)
        self.min_interval = reflex.min_interval_s if reflex else 0.0
        self.reflex_name = reflex.name if reflex else ""
        self.requested_at: float | None = None
        self.held = False
        self.every(T.TPSC_SCAN_S, self.scan)

    def scan(self) -> None:
        left, right = self.hw.whiskers()
        c = _BOTH if left and right else _LEFT if left else _RIGHT if right else 0
        if c and c != self.contact:
            self.latched = c
            self.hw.note("stimulus", kind="whisker")
            self.request()
        self.contact = c

    def request(self) -> None:
        """DATA_RDY, at most once per the reflex's min_interval (spec reflexes): a contact sooner than that is
        latched and goes with the next request; the STOP of the last one is already on its way (seed 5.2)."""
        wait = 0.0 if self.requested_at is None else self.requested_at + self.min_interval - self.now
        if wait > 0:
            if not self.held:
                self.held = True
                self.hw.after(wait, self._release)
            return
        self.requested_at = self.now
        if self.min_interval:                    # debug port: when it was raised (tracecheck's reflex_rate rule)
            self.hw.note("reflex_raised", reflex=self.reflex_name)
        self.slave_send(self.master, M.DataRdy())

    def _release(self) -> None:
        self.held = False
        if self.latched:
            self.request()

    def on_xmit_data(self, src: int, msg: M.XmitData) -> None:
        self.send(src, M.XmitDataTpsc(contact=self.latched or self.contact))
        self.latched = 0


class ISC(_Sensor, IscSkeleton):
    """seed 3.2.14: measures both axes continuously ("laufend")."""

    def start(self) -> None:
        super().start()
        self.latest = (0, 0)
        self.every(T.ISC_MEASURE_S, self.measure)

    def measure(self) -> None:
        lon, tr = self.hw.inclination()
        self.latest = (_ISC_DEG.raw(lon), _ISC_DEG.raw(tr))
        self.check_alarms(dict(enumerate(self.latest)))

    def on_set_alarm_isc(self, src: int, msg: M.SetAlarmIsc) -> None:
        self.set_alarm(msg.channel, limit_in(_ISC_DEG, M.SetAlarmIsc, msg.limit), BEYOND)

    def on_xmit_data(self, src: int, msg: M.XmitData) -> None:
        self.fetched()
        self.send(src, M.XmitDataIsc(longitudinal=self.latest[0], transverse=self.latest[1]))


class TSC(_Sensor, TscSkeleton):
    """seed 3.2.15: up to 8 probes; XMIT_DATA sends one probe at a time, an alarmed probe first."""

    def start(self) -> None:
        super().start()
        self.channel = 0
        self.latest: list[int] = []
        self.alarmed: deque[int] = deque()
        self.every(T.TSC_MEASURE_S, self.measure)

    def measure(self) -> None:
        self.latest = [_TSC_C.raw(c) for c in self.hw.temperatures()]
        for ch in self.check_alarms(dict(enumerate(self.latest))):
            if ch not in self.alarmed:
                self.alarmed.append(ch)

    def on_set_alarm_tsc(self, src: int, msg: M.SetAlarmTsc) -> None:
        self.set_alarm(msg.channel, limit_in(_TSC_C, M.SetAlarmTsc, msg.limit), ABOVE)

    def on_xmit_data(self, src: int, msg: M.XmitData) -> None:
        if not self.latest:
            self.measure()
        if self.alarmed:
            ch = self.alarmed.popleft()
        else:
            ch = self.channel
            self.channel = (ch + 1) % len(self.latest)
        if not self.alarmed:
            self.fetched()
        self.send(src, M.XmitDataTsc(channel=ch, temperature=self.latest[ch]))


class _Averaging(_Sensor):
    """LSC and PSC: measure on their own clock, send the mean of the last three (3.2.16, 3.2.17)."""

    PERIOD = 0.0
    SENSE = ABOVE

    def start(self) -> None:
        super().start()
        self.last3: deque[int] = deque(maxlen=3)
        self.every(self.PERIOD, self.measure)

    def reading(self) -> int:
        raise NotImplementedError

    def value(self) -> int:
        return _mean(list(self.last3)) if self.last3 else self.reading()

    def measure(self) -> None:
        self.last3.append(self.reading())
        self.check_alarms({0: self.value()})


class LSC(_Averaging, LscSkeleton):
    """seed 3.2.16: "mißt laufend die Umgebungshelligkeit"; alarm above a brightness."""

    PERIOD = T.LSC_MEASURE_S

    def reading(self) -> int:
        return _LSC_LX.raw(self.hw.light())

    def on_set_alarm_lsc(self, src: int, msg: M.SetAlarmLsc) -> None:
        self.set_alarm(0, limit_in(_LSC_LX, M.SetAlarmLsc, msg.limit), ABOVE)

    def on_xmit_data(self, src: int, msg: M.XmitData) -> None:
        self.fetched()
        self.send(src, M.XmitDataLsc(brightness=self.value()))


class PSC(_Averaging, PscSkeleton):
    """seed 3.2.17: battery voltage; alarm below the under-voltage limit.

    The terminal voltage sags by the internal resistance times the load: servos stalled against a wall
    pull a full battery under the limit for as long as they stall (issue 18). The battery is low when it
    stays low: the alarm compares the highest reported mean over PSC_ALARM_WINDOW_S (the level the
    battery recovers to between load peaks; battery monitors call it an under-voltage delay)."""

    PERIOD = T.PSC_MEASURE_S

    def start(self) -> None:
        super().start()
        self.means: deque[int] = deque(maxlen=max(1, round(T.PSC_ALARM_WINDOW_S / self.PERIOD)))
        self.mean_min: int | None = None      # telemetry: the lowest mean reported / the lowest level judged
        self.level_min: int | None = None

    def reading(self) -> int:
        return _PSC_V.raw(self.hw.battery())

    def measure(self) -> None:
        self.last3.append(self.reading())
        mean = self.value()
        self.means.append(mean)
        level = max(self.means)
        self.mean_min = mean if self.mean_min is None else min(self.mean_min, mean)
        self.level_min = level if self.level_min is None else min(self.level_min, level)
        self.check_alarms({0: level})

    def debug_metrics(self) -> PscDebug:
        """Debug port: alarms, the mean it reports now, and the lowest mean and judged level of the run (volts)."""
        def volts(raw: int | None) -> float | None:
            return None if raw is None else round(_PSC_V.phys(raw), 3)
        return {**super().debug_metrics(), "mean_v": volts(self.value() if self.last3 else None),
                "mean_min_v": volts(self.mean_min), "level_min_v": volts(self.level_min)}

    def on_set_alarm_psc(self, src: int, msg: M.SetAlarmPsc) -> None:
        self.set_alarm(0, limit_in(_PSC_V, M.SetAlarmPsc, msg.limit), BELOW)

    def on_xmit_data(self, src: int, msg: M.XmitData) -> None:
        self.fetched()
        self.send(src, M.XmitDataPsc(voltage=self.value()))
