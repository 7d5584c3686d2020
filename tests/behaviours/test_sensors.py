"""Sensor controllers (seed 3.2.11-3.2.17): the three-plus-three rule, SET_ALARM limits, free run."""
from __future__ import annotations

import pytest

from arachnae_proto import messages as M
from arachnae_proto.enums import RangeStatus
from arachnae_proto.network import ADDRESS_OF as A

from behaviours import tuning as T
from behaviours.runtime import BusTiming
from behaviours.spu import Record
from behaviours.units import quantizer
from tests.behaviours.rig import Rig

SPU = A["SPU"]
IR = quantizer(M.XmitDataIrrc, "center")
US = quantizer(M.XmitDataUsrc, "distance")
PSC_V = quantizer(M.XmitDataPsc, "voltage")


def feed(values):
    """A hardware reading function returning the given readings in turn, then the last one for ever."""
    values = list(values)

    def read():
        return values.pop(0) if len(values) > 1 else values[0]
    return read


def irrc(spec, readings) -> Rig:
    rig = Rig(spec, "IRRC", A["IRRC"])
    rig.board.ir_ranges = feed(readings)
    return rig


def beams(cm: float, centre: float | None = None):
    c = cm if centre is None else centre
    return (cm / 100, c / 100, cm / 100)


def test_irrc_takes_three_more_readings_when_three_spread_and_keeps_its_trust(spec):
    spread, steady = [beams(5), beams(8), beams(5)], [beams(7)] * 3
    rig = irrc(spec, spread + steady)
    rig.run(0.01)                                         # the first measurement, at power-on
    node = rig.node
    assert (node.status, node.second_sets) == (RangeStatus.IN_ORDER, 1)
    assert node.latest == (IR.raw(7),) * 3                # the mean of the second set (3.2.13)
    assert rig.frames(M.DataRdy) == []


def test_irrc_declares_itself_unreliable_when_the_second_three_spread_too(spec):
    good = [beams(7)] * 3
    bad = [beams(5), beams(9), beams(5)] * 2
    rig = irrc(spec, good + bad + [beams(9.5)])
    rig.run(T.IRRC_MEASURE_S + 0.01)
    assert rig.node.status == RangeStatus.UNRELIABLE      # seed 3.2.13: declares itself unreliable
    (_, f), = rig.frames(M.DataRdy)                       # CHOICE: a status change is announced to the SPU
    assert f.dst == SPU
    rig.inject(0.2, SPU, M.StatusReq())
    rig.inject(0.3, SPU, M.XmitData())
    rig.run(0.4)
    assert rig.frames(M.StatusAckRange)[-1][1].message.status == RangeStatus.UNRELIABLE
    # later readings are steady again, but it stays unreliable (CHOICE: until INIT) ...
    assert rig.node.status == RangeStatus.UNRELIABLE
    rig.inject(0.5, SPU, M.Init())
    rig.run(0.6)
    assert rig.node.status == RangeStatus.IN_ORDER       # ... initialised again, it trusts itself again


def test_an_unreliable_measurement_never_replaces_the_last_reliable_value(spec):
    rig = irrc(spec, [beams(7)] * 3 + [beams(2), beams(9), beams(2)] * 2 + [beams(2)])
    rig.run(T.IRRC_MEASURE_S + 0.001)                    # the second measurement spread twice
    rig.inject(rig.board.t, SPU, M.XmitData())            # fetched before the third measurement
    rig.run(T.IRRC_MEASURE_S * 1.9)
    (_, f), = rig.frames(M.XmitDataIrrc)
    assert (f.message.left, f.message.center, f.message.right) == (IR.raw(7),) * 3


def test_irrc_alarm_fires_once_on_crossing_and_rearms_with_hysteresis(spec):
    rig = Rig(spec, "IRRC", A["IRRC"])
    distance = {"cm": 9.0}
    rig.board.ir_ranges = lambda: beams(9.0, distance["cm"])
    rig.inject(0.0, SPU, M.SetAlarmIrrc.from_phys(limit=6.0))
    rig.run(0.5)
    assert rig.frames(M.DataRdy) == []
    distance["cm"] = 5.0                                  # closer than the limit (seed 3.2.13: "Unterschreiten")
    rig.run(1.0)
    assert len(rig.frames(M.DataRdy)) == 1               # once, not at every measurement
    rig.inject(1.0, SPU, M.XmitData())
    distance["cm"] = 6.5                                  # back, but within the hysteresis
    rig.run(1.5)
    distance["cm"] = 5.0
    rig.run(2.0)
    assert len(rig.frames(M.DataRdy)) == 1
    distance["cm"] = 9.0                                  # well clear: re-armed
    rig.run(2.5)
    distance["cm"] = 4.0
    rig.run(3.0)
    assert len(rig.frames(M.DataRdy)) == 2


def test_psc_sends_the_mean_of_its_last_three_and_alarms_below_the_limit(spec):
    rig = Rig(spec, "PSC", A["PSC"])
    volts = {"v": 4.8}
    rig.board.battery = lambda: volts["v"]
    rig.inject(0.0, SPU, M.SetAlarmPsc.from_phys(limit=4.4))
    rig.run(2.0)
    assert rig.frames(M.DataRdy) == []
    volts["v"] = 4.3
    rig.run(2.0 + T.PSC_MEASURE_S + 0.01)                 # one low reading: mean (4.8 + 4.8 + 4.3) / 3 > 4.4
    assert rig.frames(M.DataRdy) == []
    rig.inject(rig.board.t, SPU, M.XmitData())
    rig.run(rig.board.t + 0.1)
    (_, f), = rig.frames(M.XmitDataPsc)
    assert f.message.voltage == round((2 * PSC_V.raw(4.8) + PSC_V.raw(4.3)) / 3)   # seed 3.2.17
    rig.run(2.0 + T.PSC_ALARM_WINDOW_S - T.PSC_MEASURE_S)
    assert rig.frames(M.DataRdy) == []                    # low, but not yet for the whole window
    rig.run(2.0 + T.PSC_ALARM_WINDOW_S + 3 * T.PSC_MEASURE_S)
    (_, f), = rig.frames(M.DataRdy)                       # seed 3.2.17: under-voltage reported on its own
    assert f.dst == SPU
    assert rig.node.debug_metrics()["alarms"] == 1


def test_psc_a_load_dip_is_no_under_voltage(spec):
    """Issue 18: legs stalled against a wall pull a full battery's terminal voltage to 4.2 V for a few
    seconds (15 A through 50 mOhm); the mean of three readings falls under the limit, the battery is not low."""
    rig = Rig(spec, "PSC", A["PSC"])
    volts = {"v": 4.7}
    rig.board.battery = lambda: volts["v"]
    rig.inject(0.0, SPU, M.SetAlarmPsc.from_phys(limit=4.4))
    rig.run(3.0)
    for dip in (4.2, 4.7, 4.2, 4.7):                      # stalls, relief between them: the load, not the charge
        volts["v"] = dip
        rig.run(rig.board.t + T.PSC_ALARM_WINDOW_S * 0.8)
    assert rig.frames(M.DataRdy) == [] and rig.node.debug_metrics()["alarms"] == 0  # no alarm ...
    assert PSC_V.phys(rig.node.mean_min) < 4.4            # ... though the mean it reports did dip below


def test_isc_alarms_per_axis_beyond_the_limit_either_way(spec):
    rig = Rig(spec, "ISC", A["ISC"])
    tilt = {"deg": (3.0, 0.0)}
    rig.board.inclination = lambda: tilt["deg"]
    rig.inject(0.0, SPU, M.SetAlarmIsc.from_phys(channel=1, limit=15))
    rig.run(1.0)
    tilt["deg"] = (30.0, 0.0)                             # the longitudinal axis has no alarm set
    rig.run(2.0)
    assert rig.frames(M.DataRdy) == []
    tilt["deg"] = (0.0, -18.0)                            # transverse, downhill side: beyond 15 either way
    rig.run(3.0)
    assert len(rig.frames(M.DataRdy)) == 1
    assert rig.node.alarm_count == 1


def test_tsc_alarm_sends_the_hot_probe_first(spec):
    rig = Rig(spec, "TSC", A["TSC"])
    temps = {"c": [20.0] * 8}
    rig.board.temperatures = lambda: tuple(temps["c"])
    for ch in range(8):
        rig.inject(0.0, SPU, M.SetAlarmTsc.from_phys(channel=ch, limit=50))
    rig.run(1.5)
    temps["c"] = [20.0] * 5 + [60.0] + [20.0] * 2
    rig.run(2.5)
    assert len(rig.frames(M.DataRdy)) == 1
    rig.inject(2.5, SPU, M.XmitData())
    rig.run(2.6)
    (_, f), = rig.frames(M.XmitDataTsc)
    assert (f.message.channel, f.message.temperature) == (5, 60)


def test_lsc_alarm_above_a_brightness(spec):
    rig = Rig(spec, "LSC", A["LSC"])
    lux = {"lx": 50.0}
    rig.board.light = lambda: lux["lx"]
    rig.inject(0.0, SPU, M.SetAlarmLsc.from_phys(limit=500))
    rig.run(1.0)
    assert rig.frames(M.DataRdy) == []
    lux["lx"] = 2000.0
    rig.run(2.0)
    assert len(rig.frames(M.DataRdy)) == 1


def test_usrc_free_run_announces_the_nearest_echo_of_each_sector(spec):
    rig = Rig(spec, "USRC", A["USRC"])
    head_to_m = {h: 3.0 for h in range(360)}
    head_to_m[4] = 1.0                                    # something near at 4 degrees

    def ping(head):
        return head_to_m[head], 0.001
    rig.board.sonar_ping = ping
    rig.inject(0.0, SPU, M.FreeRun())
    sector_s = T.USRC_SECTOR_DEG * (3 * 0.001 + T.USRC_HEAD_STEP_S)
    rig.run(1.2 * sector_s)
    assert len(rig.frames(M.DataRdy)) == 1                # FREE_RUN: data announced with DATA_RDY
    rig.inject(rig.board.t, SPU, M.XmitData())
    rig.run(rig.board.t + 0.05)
    (_, f), = rig.frames(M.XmitDataUsrc)
    assert (f.message.distance, f.message.angle) == (US.raw(1.0), 4)      # the sector's minimum
    rig.run(rig.board.t + 3 * sector_s)
    assert len(rig.frames(M.DataRdy)) == 4                # one per sector, not one per degree


def test_usrc_that_does_not_trust_itself_stops_announcing(spec):
    rig = Rig(spec, "USRC", A["USRC"])
    spread = iter([1.0, 3.0, 1.0, 2.0, 4.0, 1.0])        # the first measurement: both sets spread

    def ping(head):
        return next(spread, 3.0), 0.001
    rig.board.sonar_ping = ping
    rig.inject(0.0, SPU, M.FreeRun())
    rig.run(1.0)
    assert rig.node.status == RangeStatus.UNRELIABLE
    assert rig.frames(M.DataRdy) == []                    # seed 6.2: its data is not to be trusted


def test_tpsc_raises_a_reflex_request_at_most_once_per_min_interval(spec):
    """spec reflexes whisker_stop.min_interval_ms: a contact sooner than that is latched and goes with the next."""
    interval = spec.reflexes[0].min_interval_ms / 1000
    rig = Rig(spec, "TPSC", A["TPSC"])
    for t, touch in ((1.0, (True, False)), (1.05, (False, False)), (1.1, (False, True)), (1.15, (False, False))):
        rig.run(t)
        rig.board.whisker = touch
    rig.run(1.0 + 2 * interval)
    asks = [t for t, f in rig.frames(M.DataRdy, SPU)]
    assert len(asks) == 2 and asks[1] - asks[0] >= interval - 1e-9
    assert len([1 for _t, e, d in rig.board.notes if e == "stimulus"]) == 2     # both contacts were seen


def test_an_ordinary_sensor_request_starts_after_the_reflex_one_would(spec):
    """seed 5.2 / spec arbitration reflex_lead_bits: on an idle line the TPSC (rank 0) starts first; every other
    sensor waits at least reflex_lead_bits longer, so it hears the TPSC's carrier and defers."""
    tpsc, isc = Rig(spec, "TPSC", A["TPSC"]), Rig(spec, "ISC", A["ISC"])
    isc.board.inclination = lambda: (0.0, 0.0)
    for rig in (tpsc, isc):
        rig.board.busy_until["sensor"] = 1.0            # a frame ends at 1.0 s
        rig.board.line_idle_s = lambda bus, b=rig.board: max(0.0, b.t - b.busy_until.get(bus, 0.0)) if b.t >= 1.0 else 0.0
        rig.board.after(0.999 - rig.board.t, rig.node.slave_send, SPU, M.DataRdy())
        rig.run(1.2)
    lead = spec.arbitration[spec.buses["sensor"].arbitration]["reflex_lead_bits"] / spec.buses["sensor"].baud
    (t_reflex, _), (t_other, _) = tpsc.frames(M.DataRdy)[0], isc.frames(M.DataRdy)[0]
    assert t_other - t_reflex >= lead


def test_the_spu_request_carrying_a_contact_leads_an_ordinary_one_on_the_first_bus(spec):
    """spec arbitration reflex_lead_bits on the first-level bus: after a master's frame (a polled reply may still
    come, Runtime._slave_start) the SPU's XMIT_REQ for a TPSC record is handed to the line before the master's
    defer runs out, the NP3's ordinary one at least reflex_lead_bits after it."""
    first = spec.buses["first"]
    starts = {}
    for role, reflex in (("SPU", True), ("NP3", False)):
        rig = Rig(spec, role, A[role])
        b = rig.board
        b.busy_until["first"] = 1.0
        b.line_idle_s = lambda bus, b=b: max(0.0, b.t - b.busy_until.get(bus, 0.0)) if b.t >= 1.0 else 0.0
        if reflex:
            rig.node.outbox = [Record(A["TPSC"], 0, 0, 16, 0.9)]
        b.after(0.999 - b.t, rig.node.slave_send, A["MCP"], M.XmitReq())
        rig.run(1.1)
        starts[role] = next(t for t, f in rig.frames(M.XmitReq))
    lead = spec.arbitration[first.arbitration]["reflex_lead_bits"] / first.baud
    slot_s = (spec.frame_time_us("first", 0) + first.frame_gap_us) * 1e-6      # spec arbitration.slot
    assert 1.0 + first.frame_gap_us * 1e-6 <= starts["SPU"] < 1.0 + spec.protocol.master_defer_slots * slot_s
    assert starts["NP3"] - starts["SPU"] >= lead


def test_a_slave_does_not_start_its_request_at_the_very_end_of_its_backoff_slot(spec):
    """seed 3.2.2 / spec address_backoff (scope all): after a corrupt frame the rank-0 SPU may start only inside
    slot 0 of the window. frame_loss seed 7 had it start 1e-14 s short of slot 1 (float noise), which the line
    and the trace validator read as slot 1, the next rank's; at the slot's last bit it waits for the window's end."""
    rig = Rig(spec, "SPU", A["SPU"])
    node, b = rig.node, rig.board
    assert node.rank("first") == 0
    t = BusTiming("first")
    step = spec.arbitration[spec.buses["first"].arbitration]["backoff_slots"] * t.slot_s
    window_end = 1.0 + len(node.net.requesters["first"]) * step
    b.t = 1.0
    node._open_window("first")                      # a corrupt frame ended at 1.0 s
    b.t = 1.0 + step / 2
    assert node._backoff_wait("first") == 0.0        # inside its slot: go
    for at in (1.0 + step - 1e-14, 1.0 + step - t.bit_s / 2):
        b.t = at
        assert node._backoff_wait("first") == pytest.approx(window_end - at)
