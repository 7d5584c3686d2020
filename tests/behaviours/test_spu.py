"""SPU (seed 3.2.5, 6.2): alarm set-up after POST, records to the NP3, status checks, untrusted sensors ignored."""
from __future__ import annotations

from arachnae_proto import messages as M
from arachnae_proto.enums import RangeStatus, RecordKind, TpscContact
from arachnae_proto.network import ADDRESS_OF as A

from behaviours import tuning as T
from behaviours.runtime import BusTiming
from behaviours.units import quantizer
from tests.behaviours.rig import Rig

SPU, MCP, NP3 = A["SPU"], A["MCP"], A["NP3"]
IR = quantizer(M.XmitDataIrrc, "center")
PSC_V = quantizer(M.XmitDataPsc, "voltage")
SENSORS = ("USRC", "TPSC", "IRRC", "ISC", "TSC", "LSC", "PSC")


class Bus:
    """Scripted sensors on the SPU's bus and an MCP that grants every XMIT_REQ."""

    def __init__(self) -> None:
        self.status = {"USRC": 0, "IRRC": 0}
        self.silent: set[str] = set()
        self.ir_cm = 9.0
        self.volts = 4.8

    def data(self, short: str) -> M.Message:
        if short == "IRRC":
            r = IR.raw(self.ir_cm)
            return M.XmitDataIrrc(left=255, center=r, right=255)
        if short == "USRC":
            return M.XmitDataUsrc.from_phys(distance=2.0, angle=40)
        if short == "TPSC":
            return M.XmitDataTpsc(contact=int(TpscContact.OBJ_LEFT))
        if short == "ISC":
            return M.XmitDataIsc(longitudinal=3, transverse=-6)
        if short == "TSC":
            return M.XmitDataTsc(channel=0, temperature=21)
        if short == "LSC":
            return M.XmitDataLsc(brightness=150)
        return M.XmitDataPsc(voltage=PSC_V.raw(self.volts))

    def __call__(self, f):
        m, a = f.message, f.dst
        if isinstance(m, M.XmitReq):
            return [(MCP, M.XmitGrant())]
        short = {A[s]: s for s in SENSORS}.get(a)
        if short is None or short in self.silent:
            return []
        if isinstance(m, M.IdReq):
            return [(a, M.IdAck(address=a))]
        if isinstance(m, M.StatusReq):
            if short in self.status:
                return [(a, M.StatusAckRange(status=self.status[short]))]
            return [(a, M.StatusAckOrder(status=0))]
        if isinstance(m, M.XmitData):
            return [(a, self.data(short))]
        return []


def spu(spec, until: float = 3.0) -> tuple[Rig, Bus]:
    bus = Bus()
    rig = Rig(spec, "SPU", SPU, bus)
    rig.run(until)
    return rig, bus


def records(rig, source: str | None = None, kind: int | None = None, after: float = 0.0):
    return [f.message for t, f in rig.frames(M.XmitRecord) if t >= after
            and (source is None or f.message.source == A[source]) and (kind is None or f.message.kind == kind)]


def test_after_post_every_sensor_gets_its_alarm_limits_and_the_sonar_free_runs(spec):
    rig, _ = spu(spec)
    assert [f.dst for _, f in rig.frames(M.FreeRun)] == [A["USRC"]]                  # seed 3.2.11
    (_, ir), = rig.frames(M.SetAlarmIrrc)
    assert ir.dst == A["IRRC"] and ir.message == M.SetAlarmIrrc.from_phys(limit=T.SPU_ALARM_IRRC_CM)
    assert sorted(f.message.channel for _, f in rig.frames(M.SetAlarmIsc)) == [0, 1]    # per axis
    assert sorted(f.message.channel for _, f in rig.frames(M.SetAlarmTsc)) == list(range(8))   # per probe
    assert rig.frames(M.SetAlarmLsc)[0][1].message == M.SetAlarmLsc.from_phys(limit=T.SPU_ALARM_LSC_LX)
    assert rig.frames(M.SetAlarmPsc)[0][1].message == M.SetAlarmPsc.from_phys(limit=T.SPU_ALARM_PSC_V)
    polled = {f.dst for _, f in rig.frames(M.XmitData)}
    assert A["USRC"] not in polled and A["IRRC"] in polled                          # the sonar announces itself


def test_ir_values_travel_per_beam_with_their_channel(spec):
    rig, _ = spu(spec)
    ir = records(rig, "IRRC", int(RecordKind.VALUE))
    assert {(r.channel, r.value) for r in ir} == {(0, 255), (1, IR.raw(9.0)), (2, 255)}
    assert all(r.target == NP3 for r in ir)
    isc = {r.channel: r.value for r in records(rig, "ISC")}
    assert isc == {0: 3, 1: (-6) & 0xFF}                   # int8 as its two's complement byte


def test_an_alarm_announced_by_a_sensor_becomes_an_alarm_record(spec):
    rig, bus = spu(spec)
    bus.volts = 4.3                                         # below SPU_ALARM_PSC_V
    rig.inject(3.0, A["PSC"], M.DataRdy())
    rig.run(4.0)
    alarm, = records(rig, "PSC", int(RecordKind.ALARM))
    assert alarm.value == PSC_V.raw(4.3) and alarm.target == NP3


def test_a_status_change_found_by_the_status_poll_goes_to_the_np3_and_ir_data_stops(spec):
    rig, bus = spu(spec)
    bus.status["IRRC"] = int(RangeStatus.UNRELIABLE)
    rig.run(3.0 + 2 * T.SPU_STATUS_EVERY_S + 0.5)
    st, = records(rig, "IRRC", int(RecordKind.STATUS))
    assert st.value == RangeStatus.UNRELIABLE and st.channel == 0
    t_status = next(t for t, f in rig.frames(M.XmitRecord) if f.message == st)
    bus.ir_cm = 3.0                                         # would be news, but the sensor is not trusted (6.2)
    rig.run(t_status + 3.0)
    assert records(rig, "IRRC", int(RecordKind.VALUE), after=t_status + 0.2) == []


def test_an_ir_status_change_announced_with_data_rdy_is_fetched_at_once(spec):
    rig, bus = spu(spec)
    bus.status["IRRC"] = int(RangeStatus.UNRELIABLE)
    rig.inject(3.0, A["IRRC"], M.DataRdy())
    rig.run(3.4)
    assert [r.value for r in records(rig, "IRRC", int(RecordKind.STATUS))] == [RangeStatus.UNRELIABLE]


def test_an_unreliable_sonar_is_ignored(spec):
    """seed 6.2: the US system is declared untrustworthy and its data ignored."""
    rig, bus = spu(spec)
    rig.inject(3.0, A["USRC"], M.DataRdy())
    rig.run(3.5)
    assert len(records(rig, "USRC", int(RecordKind.VALUE))) == 1
    bus.status["USRC"] = int(RangeStatus.UNRELIABLE)
    rig.run(3.5 + 2 * T.SPU_STATUS_EVERY_S + 0.5)
    assert [r.value for r in records(rig, "USRC", int(RecordKind.STATUS))] == [RangeStatus.UNRELIABLE]
    t = rig.board.t
    for k in range(5):
        rig.inject(t + 0.3 * k, A["USRC"], M.DataRdy())
    rig.run(t + 2.0)
    assert len(records(rig, "USRC", int(RecordKind.VALUE))) == 1
    assert rig.node.debug_metrics()["ignored"] == 5


def test_a_sensor_that_stops_answering_is_out_of_order(spec):
    rig, bus = spu(spec)
    bus.silent.add("IRRC")
    rig.run(5.0)
    st, = records(rig, "IRRC", int(RecordKind.STATUS))
    assert st.value == RangeStatus.OUT_OF_ORDER
    assert rig.node.debug_metrics()["silent"] == 1


def test_a_whisker_contact_is_fetched_and_forwarded(spec):
    rig, _ = spu(spec)
    rig.inject(3.0, A["TPSC"], M.DataRdy())
    rig.run(3.5)
    rec, = records(rig, "TPSC", after=3.0)
    assert (rec.kind, rec.value) == (RecordKind.VALUE, TpscContact.OBJ_LEFT)


def test_after_post_the_close_range_is_polled_first_and_forwarded(spec):
    """seed 5.2: switched on touching a wall, the TPSC's DATA_RDY came while the SPU was still in POST and was
    lost; the SPU asks the IR and the whiskers (tuning.SPU_FIRST_POLL) before setting up any alarm, and the
    NP3 gets what they sense (the scripted whisker touches on the left)."""
    rig, _ = spu(spec)
    to_sensors = [(type(f.message), f.dst) for _t, _bus, f in rig.sent if f.dst != A["MCP"]]
    set_up = next(i for i, (cls, _dst) in enumerate(to_sensors) if cls.__name__.startswith("SetAlarm"))
    assert M.XmitData not in [cls for cls, _dst in to_sensors[:set_up - 2]]        # none during the POST
    assert to_sensors[set_up - 2:set_up] == [(M.XmitData, A[r]) for r in T.SPU_FIRST_POLL]
    rec, = [r for r in records(rig, "TPSC") if r.kind == RecordKind.VALUE]
    assert rec.value == TpscContact.OBJ_LEFT


def test_asked_for_its_id_again_after_reporting_the_spu_runs_a_new_post(spec):
    """seed 6.3: a POST at run time reaches the sensors: the SPU identifies its slaves again."""
    rig, bus = spu(spec)
    rig.inject(3.0, MCP, M.PostQuery())
    rig.run(3.5)
    assert len(rig.frames(M.PostReport)) == 1
    before = len(rig.frames(M.IdReq))
    bus.silent.add("TSC")
    rig.inject(4.0, MCP, M.IdReq())
    rig.inject(4.1, MCP, M.PostQuery())
    rig.run(8.0)
    assert len(rig.frames(M.IdReq)) >= before + len(SENSORS)
    reports = [f.message for _, f in rig.frames(M.PostReport)]
    assert reports[0].missing == () or list(reports[0].missing) == []
    assert list(reports[-1].missing) == [A["TSC"]]
    assert rig.node.debug_metrics()["posts"] == 2
    polls_after = [t for t, f in rig.frames(M.XmitData) if t > 7.0]
    assert polls_after                                      # polling resumed after the new POST


def test_a_sensor_announcing_again_before_its_fetch_goes_out_is_fetched_once(spec):
    """seed 3.2.2 / arbitration model: one request per slave. DATA_RDYs while the sonar's fetch still waits for the
    line add none (the free-running USRC had piled up nine, every other sensor past K); an urgent fetch is not
    folded into an ordinary poll of the same sensor still waiting (that one comes last)."""
    rig, _ = spu(spec)
    t = rig.board.t
    for k in range(3):
        rig.inject(t + 0.001 * k, A["USRC"], M.DataRdy())
    rig.node.request(A["LSC"], M.XmitData(), (M.XmitDataLsc,))          # an ordinary poll, waiting
    rig.inject(t + 0.003, A["LSC"], M.DataRdy())                        # an alarm: fetched as urgent
    rig.run(t + 0.003)
    assert rig.node.waiting(A["LSC"], M.XmitData, 1)
    rig.run(t + 1.0)
    assert len([1 for at, _f in rig.frames(M.XmitData, A["USRC"]) if at >= t]) == 1
    assert rig.node.debug_metrics()["coalesced"] == 2



def test_a_whisker_fetch_goes_ahead_of_a_poll_waiting_to_resend_after_a_collision(spec):
    """spec reflexes (seed 5.2): a poll whose frame collided is off the wire while it waits out the slaves' window;
    the whisker's fetch queued meanwhile goes first (worst_contention seed 1: it waited two resend windows behind
    a PSC poll, and the LSC past K)."""
    rig, _ = spu(spec)
    t = rig.board.t
    hits: list[float] = []

    def first_psc_poll(f) -> bool:
        if f.dst == A["PSC"] and isinstance(f.message, M.XmitData) and not hits:
            hits.append(rig.board.t)
            return True
        return False

    rig.garble = first_psc_poll
    rig.node.request(A["PSC"], M.XmitData(), (M.XmitDataPsc,))
    while not hits and rig.board.t < t + 2.0:
        rig.run(rig.board.t + 0.005)
    assert hits
    rig.run(hits[0] + 0.05)                                 # the collided frame has ended: its resend waits
    rig.inject(rig.board.t, A["TPSC"], M.DataRdy())
    rig.run(t + 3.0)
    tpsc = [at for at, _f in rig.frames(M.XmitData, A["TPSC"]) if at > hits[0]]
    psc = [at for at, _f in rig.frames(M.XmitData, A["PSC"]) if at > hits[0]]
    assert tpsc and psc and tpsc[0] < psc[0]
