"""SPU (seed 3.2.5): master of the sensor bus; sets the sensors up, polls them and forwards to the NP3.

After its POST the SPU sets up every sensor's SET_ALARM limit (tuning).
Then it polls the sensors round-robin (tuning.SPU_CYCLE, the IRRC every
second poll because close range matters most, 5.2) and asks the range
sensors for their status in turn. The sonar's poll is one angle of a scan
the SPU drives (HEAD_SET_ABS, DO_MEASURE, XMIT_DATA; 3.2.11): a sweep ahead
of the heading with, every few angles, one of the rest of the circle for the
map. Unlike the USRC's free-running circle, whose sector minima came up to a
sector's scan late and at an unknown time, the SPU knows when each echo was
pinged (issue 17). A DATA_RDY is served before the next poll: from the TPSC
a contact, from any other sensor an alarm or a status change. What the NP3
needs travels as XMIT_RECORDs through the MCP (3.2.2): VALUE records
(rate-limited per sensor channel), ALARM records for a crossed limit, STATUS
records when a sensor's status changes, each with its age (how long ago it
was measured). A sensor that stops answering counts as OUT_OF_ORDER; a range
sensor that is not IN_ORDER is not trusted and its data is ignored (6.2).
"""
from __future__ import annotations

import math
from typing import Any, NamedTuple, TypedDict

from arachnae_proto import messages as M
from arachnae_proto.enums import IscAxis, RangeStatus, RecordKind
from arachnae_proto.network import ADDRESS_OF, NODES
from arachnae_proto.skeletons.spu import SpuSkeleton

from behaviours import tuning as T
from behaviours.post import PostMaster
from behaviours.runtime import PRIORITY_REFLEX, Runtime, slaves_of
from behaviours.sensors import ABOVE, BELOW, BEYOND, AlarmLimit, limit_in
from behaviours.units import RECORD_QUANTIZER, XMIT_DATA_OF, age_byte, record_byte, values_quantizer

# each sensor role's STATUS_ACK layout; the range sensors are the ones with UNRELIABLE (3.2.11, 3.2.13)
STATUS_OF = {role: cls for cls in (M.StatusAckRange, M.StatusAckOrder) for role in cls.SENDERS}
RANGE = tuple(M.StatusAckRange.SENDERS)
_IN_ORDER, _OUT_OF_ORDER = int(RangeStatus.IN_ORDER), int(RangeStatus.OUT_OF_ORDER)   # same codes in ORDER_STATUS
_VALUE, _ALARM, _STATUS = int(RecordKind.VALUE), int(RecordKind.ALARM), int(RecordKind.STATUS)
_KIND_NAME = {int(k): k.name.lower() for k in RecordKind}
_USRC = RECORD_QUANTIZER["USRC"]       # the echo's distance (m); its top code: nothing within range (3.2.11)


def channels(role: str, msg: Any) -> dict[int, int]:
    """A sensor's reply as {record channel: raw value} (spec record_values: the channel is a field's position,
    IRRC beam, ISC axis, or the value of the record_channel field, USRC head angle, TSC probe)."""
    r = M.RECORD_VALUES[role]
    if r.channel is not None:
        (only,) = r.fields
        return {getattr(msg, r.channel): getattr(msg, only)}
    return {ch: getattr(msg, f) for ch, f in enumerate(r.fields)}


class Record(NamedTuple):
    """A record waiting for the MCP's grant: what XMIT_RECORD carries, and when its value was measured."""
    source: int
    kind: int
    channel: int
    value: int
    measured_at: float


class SonarScan:
    """The angles (body frame, 0..359) of the sonar scan the SPU drives, one per poll (issue 17): the sweep ahead of
    the heading, and every SPU_SCAN_ROUND_EVERY-th angle one off it: mostly a side angle, the two sides in turn (a
    wall alongside needs an echo every few seconds: with the whole circle in turn a side came round every ~34 s
    and wall_follow lost its wall at a corner), between them one step round the rest of the circle, for the map.
    While an echo from straight ahead (within SPU_SCAN_NEAR_DEG) is nearer than SPU_SCAN_NEAR_M, every angle is
    one of the sweep (seed 5.1.2: find obstacles in time): a step off it had the ahead angles come round 1.2 s
    apart with a wall 0.4 m ahead, and the avoidance's turn began so close that a whisker touched it
    (sonar_first seed 11)."""

    def __init__(self) -> None:
        edge = max((abs(a) for a in T.SPU_SCAN_AHEAD_DEG), default=0)
        self.ahead = [a % 360 for a in T.SPU_SCAN_AHEAD_DEG]
        self.sides = [a % 360 for a in T.SPU_SCAN_SIDE_DEG]
        self.round = [a for a in range(edge + T.SPU_SCAN_ROUND_STEP_DEG, 360 - edge, T.SPU_SCAN_ROUND_STEP_DEG)
                      if a not in self.sides]
        self.steps = self.ahead_i = self.round_i = self.side_i = self.off_i = 0
        self.ahead_m: dict[int, float] = {}       # the last echo (m, inf: none) at each angle straight ahead

    def heard(self, angle: int, metres: float | None) -> None:
        """An echo of the scan at `angle` (None: nothing within the sonar's range)."""
        if abs((angle + 180) % 360 - 180) <= T.SPU_SCAN_NEAR_DEG:
            self.ahead_m[angle % 360] = math.inf if metres is None else metres

    def near(self) -> bool:
        """Something straight ahead is near (seed 5.1.2): the scan stays on the sweep."""
        return min(self.ahead_m.values(), default=math.inf) < T.SPU_SCAN_NEAR_M

    def next(self) -> int:
        self.steps += 1
        if (self.round or self.sides) and self.steps % T.SPU_SCAN_ROUND_EVERY == 0 and not self.near():
            self.off_i += 1
            rest_turn = self.off_i % (T.SPU_SCAN_SIDES_PER_ROUND + 1) == 0
            if self.round and (rest_turn or not self.sides):
                self.round_i += 1
                return self.round[(self.round_i - 1) % len(self.round)]
            self.side_i += 1
            return self.sides[(self.side_i - 1) % len(self.sides)]
        self.ahead_i += 1
        return self.ahead[(self.ahead_i - 1) % len(self.ahead)]


def alarm_setup() -> list[tuple[str, M.Message, list[tuple[int, AlarmLimit]]]]:
    """The SET_ALARM frames for each sensor role with the limits (in the data's raw steps) they set, per channel."""
    # each limit in the raw steps of the record values it is compared with (spec compared_with)
    q = {role: values_quantizer(a.data) for role, a in M.ALARM_THRESHOLDS.items()}
    ir, isc, tsc, lsc, psc = (q[role] for role in ("IRRC", "ISC", "TSC", "LSC", "PSC"))
    out: list[tuple[str, M.Message, list[tuple[int, AlarmLimit]]]] = []
    m: M.Message = M.SetAlarmIrrc.from_phys(limit=T.SPU_ALARM_IRRC_CM)           # seed 3.2.13
    beams = range(len(M.ALARM_THRESHOLDS["IRRC"].data.fields))                   # one limit for every beam
    out.append(("IRRC", m, [(b, AlarmLimit(limit_in(ir, M.SetAlarmIrrc, m.limit), BELOW, 0)) for b in beams]))
    for axis in IscAxis:                                                          # seed 3.2.14
        m = M.SetAlarmIsc.from_phys(channel=int(axis), limit=T.SPU_ALARM_ISC_DEG[int(axis)])
        out.append(("ISC", m, [(int(axis), AlarmLimit(limit_in(isc, M.SetAlarmIsc, m.limit), BEYOND, 0))]))
    probes = next(f for f in M.SetAlarmTsc.FIELDS if f.name == "channel").conv
    for ch in range(probes.lo, probes.hi + 1):                                   # seed 3.2.15
        m = M.SetAlarmTsc.from_phys(channel=ch, limit=T.SPU_ALARM_TSC_C)
        out.append(("TSC", m, [(ch, AlarmLimit(limit_in(tsc, M.SetAlarmTsc, m.limit), ABOVE, 0))]))
    m = M.SetAlarmLsc.from_phys(limit=T.SPU_ALARM_LSC_LX)                         # seed 3.2.16
    out.append(("LSC", m, [(0, AlarmLimit(limit_in(lsc, M.SetAlarmLsc, m.limit), ABOVE, 0))]))
    m = M.SetAlarmPsc.from_phys(limit=T.SPU_ALARM_PSC_V)                          # seed 3.2.17
    out.append(("PSC", m, [(0, AlarmLimit(limit_in(psc, M.SetAlarmPsc, m.limit), BELOW, 0))]))
    return out


class SpuRecords(TypedDict):
    value: int
    alarm: int
    status: int


class SpuDebug(TypedDict):
    """SPU.debug_metrics(): metrics.json `nodes.SPU` (sim2d.metrics checks expectations on it at load)."""
    records: SpuRecords
    ignored: int
    silent: int
    untrusted_values: int
    coalesced: int                  # DATA_RDYs whose fetch was still waiting (one request per slave)
    values: dict[str, int]          # role -> records of values forwarded
    status: dict[str, int]          # role -> its status code
    posts: int


class SPU(PostMaster, Runtime, SpuSkeleton):
    def start(self) -> None:
        self.sensors = {NODES[a].role: a for a in slaves_of(self.master_bus)}
        self.live: list[str] = []
        self.status: dict[str, int] = {}
        self.misses: dict[str, int] = {}
        self.limits: dict[tuple[str, int], AlarmLimit] = {}
        self.outbox: list[Record] = []
        self.last_fwd: dict[tuple[str, int], tuple[float, int]] = {}
        self.last_record: Record | None = None
        self.scan = SonarScan()
        self.free_run: set[str] = set()
        self.pinged_at: float | None = None      # when the last DO_MEASURE reached the USRC (its echo heard)
        self.requested_at: float | None = None
        self.posting = False
        self.polling = False
        self.cycle_i = self.status_i = 0
        self.polled: str | None = None      # the role of the poll cycle's last XMIT_DATA
        self.next_status = 0.0
        self.counts = {"value": 0, "alarm": 0, "status": 0, "ignored": 0, "silent": 0, "untrusted": 0, "coalesced": 0}
        self.values: dict[str, int] = {}
        self.run_post(self.post_done)

    # --- POST and set-up ---------------------------------------------------------------
    def run_post(self, done: Any = None) -> None:
        self.posting = True            # the poll loop pauses: POST needs the bus to itself at the end
        super().run_post(done)

    def post_status(self, a: int, msg: M.Message) -> None:
        """A sensor's STATUS_ACK during POST updates what the SPU knows of it."""
        if a in NODES and NODES[a].role in STATUS_OF:
            self.set_status(NODES[a].role, msg.status)       # type: ignore[attr-defined]

    def post_done(self, missing: list[int]) -> None:
        self.posting = False
        self.live = [r for r, a in self.sensors.items() if a not in missing]
        for role in T.SPU_FIRST_POLL:  # seed 5.2: the close range first (a wall touched at power-on: the TPSC's
            if role in self.live:      # DATA_RDY then found no SPU to fetch it); the NP3 does not step before
                self.request(self.sensors[role], M.XmitData(), (XMIT_DATA_OF[role],),
                             lambda s, m, role=role: self.got(role, m, False), lambda role=role: self.missed(role))
        if "USRC" in self.live and not T.SPU_SCAN_AHEAD_DEG:   # seed 3.2.11: no scan of its own: the sonar
            self.free_run.add("USRC")                          # scans its circle and announces each sector
            self.request(self.sensors["USRC"], M.FreeRun())
        # seed 3.2.13-3.2.17: the SPU sets up the alarm limits of every sensor present
        for role, msg, limits in alarm_setup():
            if role in self.live:
                self.request(self.sensors[role], msg)
                self.limits.update({(role, ch): lim for ch, lim in limits})
        if not self.polling:
            self.polling = True
            self.poll()

    # --- polling -------------------------------------------------------------------------
    def poll(self) -> None:
        if self.posting:
            self.polling = False
            return
        ranged = [r for r in RANGE if r in self.live]
        if ranged and self.now >= self.next_status:         # seed 6.2: the range sensors' status, in turn
            self.next_status = self.now + T.SPU_STATUS_EVERY_S
            role = ranged[self.status_i % len(ranged)]
            self.status_i += 1
            self.request(self.sensors[role], M.StatusReq(), (STATUS_OF[role],),
                         lambda s, m, role=role: (self.set_status(role, m.status), self.answered(role), self.poll()),
                         lambda role=role: (self.missed(role), self.poll()))
            return
        cycle = [r for r in T.SPU_CYCLE if r in self.live and r not in self.free_run]
        if not cycle:
            self.hw.after(T.SPU_STATUS_EVERY_S, self.poll)
            return
        role = cycle[self.cycle_i % len(cycle)]
        self.cycle_i += 1
        self.polled = role
        if role == "USRC":
            self.sonar_step()
            return
        self.request(self.sensors[role], M.XmitData(), (XMIT_DATA_OF[role],),
                     lambda s, m, role=role: (self.got(role, m, False), self.poll()),
                     lambda role=role: (self.missed(role), self.poll()))

    def sonar_step(self) -> None:
        """seed 3.2.11: one angle of the scan the SPU drives: turn the head, ping, fetch the echo. The echo keeps
        the time of its ping (issue 17: the NP3 places it at the pose it had then)."""
        usrc, angle = self.sensors["USRC"], self.scan.next()
        self.pinged_at = None

        def echo(s: int, m: M.XmitDataUsrc) -> None:
            if m.angle == angle and self.pinged_at is not None:    # else the measurement did not succeed
                self.scan.heard(angle, None if m.distance >= _USRC.hi else _USRC.phys(m.distance))
                self.got("USRC", m, False, self.pinged_at)
            else:
                self.answered("USRC")
            self.poll()
        self.request(usrc, M.HeadSetAbs(angle=angle))
        self.request(usrc, M.DoMeasure())
        self.request(usrc, M.XmitData(), (M.XmitDataUsrc,), echo, lambda: (self.missed("USRC"), self.poll()))

    def on_echo(self, bus: str, sent: bytes, heard: bytes) -> None:
        """The DO_MEASURE frame's clean echo: the USRC has it now and pings (the echo's time, issue 17)."""
        cur = self.links[self.master_bus].current if self.master_bus == bus else None
        if cur is not None and isinstance(cur.msg, M.DoMeasure) and sent == heard:
            self.pinged_at = self.now
        super().on_echo(bus, sent, heard)

    def answered(self, role: str) -> None:
        self.misses[role] = 0

    def missed(self, role: str) -> None:
        """No answer even after the spec's retry; SPU_SILENT_POLLS in a row: the sensor is OUT_OF_ORDER."""
        self.misses[role] = self.misses.get(role, 0) + 1
        if self.misses[role] >= T.SPU_SILENT_POLLS:
            if self.status.get(role, _IN_ORDER) != _OUT_OF_ORDER:
                self.counts["silent"] += 1
            self.set_status(role, _OUT_OF_ORDER)

    def on_data_rdy(self, src: int, msg: M.DataRdy) -> None:
        role = NODES[src].role
        if role not in XMIT_DATA_OF or role not in self.live:
            return
        # spec reflexes (seed 5.2): a reflex source's data is fetched before anything still waiting out its defer
        priority = max(PRIORITY_REFLEX if self.net.reflex_from(src) is not None else 0, 1)
        if self.waiting(src, M.XmitData, 0 if role in self.free_run else priority):   # its fetch may wait its turn
            # seed 3.2.2 / arbitration model: one request per slave, served in the order they got through. An urgent
            # fetch still waiting gets the newest data; queueing one per DATA_RDY let the free-running USRC pile up
            # nine and every other sensor wait behind them (worst_contention seed 6: past K on the sensor bus)
            self.counts["coalesced"] += 1
            return
        if role in self.free_run:                  # a free-running sonar's sector: pinged some time before
            if self.status.get(role, _IN_ORDER) != _IN_ORDER:
                self.counts["ignored"] += 1       # seed 6.2: an untrustworthy sensor's data is ignored
                return
            # seed 5.2: ahead of the poll cycle, but not of a poll already waiting: the USRC announcing close
            # echoes every ~0.12 s kept the IR poll behind a new fetch for 2.7 s while the robot walked into a
            # corner (start_in_corner); now the fetches and the polls take turns
            polling = self.polled is not None and self.waiting(self.sensors[self.polled], M.XmitData)
            self.request(src, M.XmitData(), (XMIT_DATA_OF[role],), lambda s, m, role=role: self.got(role, m, False),
                         lambda role=role: self.missed(role), urgent=not polling)
            return
        event = role != "TPSC"                     # anything else announces an alarm or a status change
        if role in RANGE:                          # its status first: is the data to be trusted (6.2)
            self.request(src, M.StatusReq(), (STATUS_OF[role],), lambda s, m, role=role: self.set_status(role, m.status),
                         lambda role=role: self.missed(role), urgent=True)
        self.request(src, M.XmitData(), (XMIT_DATA_OF[role],), lambda s, m, role=role: self.got(role, m, event),
                     lambda role=role: self.missed(role), priority=priority)

    # --- what the sensors said -------------------------------------------------------------
    def set_status(self, role: str, code: int) -> None:
        old = self.status.get(role, _IN_ORDER)
        self.status[role] = code
        if code == old:
            return
        self.hw.note("sensor_status_change", node=role, status=code)
        self.record(role, _STATUS, 0, code)       # seed 6.2: the NP3 (and the MCP on the way) learn it

    def got(self, role: str, msg: M.Message, event: bool, measured_at: float | None = None) -> None:
        """A sensor's reply: records for the NP3 (`measured_at`: when the value was measured, if not just now)."""
        at = self.now if measured_at is None else measured_at
        self.answered(role)
        if role not in RANGE and self.status.get(role, _IN_ORDER) == _OUT_OF_ORDER:
            self.set_status(role, _IN_ORDER)       # it answers again
        if role in RANGE and self.status.get(role, _IN_ORDER) != _IN_ORDER:
            self.counts["ignored"] += 1            # seed 6.2: not trustworthy, its data is ignored
            return
        change, refresh = T.SPU_FORWARD.get(role, (0, 0.0))
        for ch, v in channels(role, msg).items():
            lim = self.limits.get((role, ch))
            if event and lim is not None and lim.beyond(v):
                self.last_fwd[(role, ch)] = (self.now, v)
                self.record(role, _ALARM, ch, v, at)   # the limit set with SET_ALARM was crossed
                continue
            last = self.last_fwd.get((role, ch))
            changed = change is not None and last is not None and abs(v - last[1]) >= max(change, 1)
            if last is None or changed or self.now - last[0] >= refresh:
                self.last_fwd[(role, ch)] = (self.now, v)
                self.record(role, _VALUE, ch, v, at)

    # --- records to the NP3 through the MCP (seed 3.2.2) -----------------------------------
    def record(self, role: str, kind: int, channel: int, value: int, measured_at: float | None = None) -> None:
        src = self.sensors[role]
        rec = Record(src, kind, channel, record_byte(value),  # signed values as their two's complement byte
                     self.now if measured_at is None else measured_at)
        self.counts[_KIND_NAME[kind]] += 1
        if kind != _STATUS:
            self.values[role] = self.values.get(role, 0) + 1
            if role in RANGE and self.status.get(role, _IN_ORDER) != _IN_ORDER:
                self.counts["untrusted"] += 1                # must stay 0 (6.2): checked by the scenarios
        if self.net.reflex_from(src) is not None:            # spec reflexes (5.2): a reflex record goes first of all
            self.outbox.insert(0, rec)
        elif kind == _VALUE and role != "TPSC":              # a newer value replaces one still waiting
            self.outbox = [r for r in self.outbox if not (r.kind == _VALUE and r.source == src and r.channel == channel)]
            self.outbox.append(rec)
        else:                                     # alarms, status changes and contacts go first (5.2)
            i = next((i for i, r in enumerate(self.outbox) if r.kind == _VALUE), len(self.outbox))
            self.outbox.insert(i, rec)
        if self.requested_at is None:
            self.ask_bus()

    def reflex_request(self, bus: str) -> bool:
        """Our XMIT_REQ carries a reflex when the record it will fetch comes from a reflex source (spec reflexes)."""
        return bool(self.outbox) and self.net.reflex_from(self.outbox[0].source) is not None

    def ask_bus(self) -> None:
        self.requested_at = self.now
        self.slave_send(ADDRESS_OF["MCP"], M.XmitReq())
        self.hw.after(T.SPU_XMIT_RETRY_S, self._ask_again, self.requested_at)

    def _ask_again(self, asked: float) -> None:
        if self.outbox and self.requested_at == asked:      # no grant since: the request may be lost
            self.ask_bus()

    def on_xmit_grant(self, src: int, msg: M.XmitGrant) -> None:
        self.requested_at = None
        if not self.outbox:
            if self.last_record is not None:   # a repeated grant: the record did not get through
                self.send_record(src, self.last_record)
            return
        self.last_record = self.outbox.pop(0)
        self.send_record(src, self.last_record)
        if self.outbox:
            self.ask_bus()

    def send_record(self, mcp: int, r: Record) -> None:
        """XMIT_RECORD (3.2.2) with the value's age now (issue 17)."""
        self.send(mcp, M.XmitRecord(target=ADDRESS_OF["NP3"], source=r.source, kind=r.kind, channel=r.channel,
                                    value=r.value, age=age_byte(self.now - r.measured_at)))

    def debug_metrics(self) -> SpuDebug:
        """Records forwarded per kind, data ignored (6.2), sensors declared silent, and the status of each."""
        return {"records": {k: self.counts[k] for k in ("value", "alarm", "status")},
                "ignored": self.counts["ignored"], "silent": self.counts["silent"],
                "untrusted_values": self.counts["untrusted"], "coalesced": self.counts["coalesced"],
                "values": dict(sorted(self.values.items())),
                "status": {r: self.status.get(r, _IN_ORDER) for r in self.live},
                "posts": self.post_runs}
