"""Sensor controllers (seed 3.2.11-3.2.17): readings quantised into the spec's encodings; TPSC and range sensor rules.

The JAC is tested in test_jac.py."""
from __future__ import annotations

from arachnae_proto import messages as M
from arachnae_proto.enums import IscAxis, RangeStatus, TpscContact

from behaviours.units import XMIT_DATA_OF, quantizer
from tests.behaviours.rig import Rig

SPU = 0x04


def test_seed_encoding_tables_saturate_like_an_adc():
    lsc = quantizer(M.XmitDataLsc, "brightness")
    assert [lsc.raw(x) for x in (0.1, 1, 10, 100, 1000)] == [0, 64, 128, 192, 255]        # seed 3.2.16
    assert lsc.raw(0.01) == 0 and lsc.raw(1e6) == 255
    tsc = quantizer(M.XmitDataTsc, "temperature")
    assert [tsc.raw(c) & 0xFF for c in (-20, 0, 100)] == [0b11101100, 0, 0b01100100]        # seed 3.2.15
    assert tsc.raw(150) == 100 and tsc.raw(-40) == -20
    us = quantizer(M.XmitDataUsrc, "distance")
    assert (us.raw(0), us.raw(10), us.raw(25), us.raw(5)) == (0, 255, 255, 128)            # seed 3.2.11: 0..10 m
    ir = quantizer(M.XmitDataIrrc, "center")
    assert (ir.raw(10), ir.raw(5)) == (255, 128)                                           # seed 3.2.13: 0..10 cm
    psc = quantizer(M.XmitDataPsc, "voltage")
    assert psc.raw(3.0) == psc.raw(4.2) < psc.raw(4.6) < psc.raw(5.0) == psc.raw(9)        # seed 3.2.17
    assert psc.phys(psc.raw(4.6)) == 4.6


def test_each_sensor_answers_xmit_data_with_its_own_record_from_the_spec(spec):
    """seed 3.2.11: XMIT_DATA_OF comes from the sensor bus's fetch_message and the records marked in the spec,
    one per sensor role, each sent by that role to the SPU (not from the messages' seed names)."""
    sensor = next(b for b in spec.buses.values() if b.fetch_message == M.XmitData.NAME)
    roles = {n.role for n in spec.slaves(sensor.name)}
    assert set(XMIT_DATA_OF) == roles
    for role, cls in XMIT_DATA_OF.items():
        assert cls.RECORD and cls.SENDERS == (role,) and cls is not M.XmitData
    assert M.FETCHED_RECORDS[M.XmitGrant]["UIC_RCP"] == (M.Move, M.PostReq)     # longest first


def test_record_values_and_alarm_thresholds_are_the_spec_s():
    """seed 3.2.2, 6.2: each sensor's data record names the fields its records carry (spec record_values), the SPU
    splits a reply into channels by it and the NP3 decodes with its encoding; each SET_ALARM threshold names the
    record values it is compared with (a field's compared_with)."""
    from behaviours.np3 import decode
    from behaviours.spu import channels
    assert {role: r.message for role, r in M.RECORD_VALUES.items()} == XMIT_DATA_OF
    assert channels("IRRC", M.XmitDataIrrc(left=10, center=20, right=30)) == {0: 10, 1: 20, 2: 30}   # beam: position
    assert channels("USRC", M.XmitDataUsrc(distance=7, angle=270)) == {270: 7}                      # head angle field
    assert channels("ISC", M.XmitDataIsc(longitudinal=-5, transverse=3)) == {
        int(IscAxis.LONGITUDINAL): -5, int(IscAxis.TRANSVERSE): 3}
    assert channels("TPSC", M.XmitDataTpsc(contact=int(TpscContact.OBJ_BOTH))) == {0: int(TpscContact.OBJ_BOTH)}
    assert decode("IRRC", 255) == 10.0 and decode("ISC", 256 - 5) == -5.0       # signed fields: two's complement
    set_alarm = {cls for cls in M.MESSAGES if cls.SEED_NAME == "SET_ALARM"}
    assert {a.message for a in M.ALARM_THRESHOLDS.values()} == set_alarm
    for role, a in M.ALARM_THRESHOLDS.items():
        assert a.message.RECEIVERS == (role,) and a.data is M.RECORD_VALUES[role] and a.limit == "limit"


def test_tpsc_initiates_with_data_rdy_and_reports_the_whisker(spec):
    rig = Rig(spec, "TPSC", 0x28)
    rig.run(0.5)
    assert rig.frames(M.DataRdy) == []
    rig.board.whisker = (True, False)
    rig.run(0.6)
    (t, f), = rig.frames(M.DataRdy)                           # seed 3.2.12: the TPSC always initiates
    assert f.dst == SPU and 0.5 < t <= 0.6
    rig.board.whisker = (False, False)
    rig.inject(0.7, SPU, M.XmitData())
    rig.run(0.8)
    (_, f), = rig.frames(M.XmitDataTpsc)
    assert f.message.contact == TpscContact.OBJ_LEFT          # latched until fetched


def test_tpsc_waits_for_the_reply_window_before_its_own_request(spec):
    """A slave's DATA_RDY must not start in the turnaround after a master's frame, where a reply is due."""
    rig = Rig(spec, "TPSC", 0x28)
    rig.run(0.5)
    rig.board.busy_until["sensor"] = 0.51                     # another node's frame on the line until 0.51
    rig.board.whisker = (False, True)
    rig.run(0.6)
    (t, _), = rig.frames(M.DataRdy)
    turnaround = spec.buses["sensor"].turnaround_us * 1e-6
    assert t > 0.51 + turnaround


def test_usrc_takes_three_more_readings_and_only_then_declares_itself_unreliable(spec):
    """seed 3.2.11: three readings averaged; spread too far: three more; spread again: UNRELIABLE."""
    us = quantizer(M.XmitDataUsrc, "distance")
    rig = Rig(spec, "USRC", 0x27)
    rig.board.sonar = [(d, 0.01) for d in (1.0, 3.0, 1.0, 2.0, 2.0, 2.1)]    # first set spread, second fine
    rig.inject(0.1, SPU, M.DoMeasure())
    rig.inject(0.2, SPU, M.StatusReq())
    rig.inject(0.3, SPU, M.XmitData())
    rig.run(0.4)
    assert rig.board.sonar == []                              # six pings: the second set was taken
    (_, f), = rig.frames(M.StatusAckRange)
    assert f.message.status == RangeStatus.IN_ORDER
    (_, f), = rig.frames(M.XmitDataUsrc)
    assert f.message.distance == round((us.raw(2.0) + us.raw(2.0) + us.raw(2.1)) / 3)   # the second set's mean
    rig.board.sonar = [(d, 0.01) for d in (1.0, 3.0, 1.0, 2.0, 4.0, 1.0)]    # both sets spread
    rig.inject(0.5, SPU, M.DoMeasure())
    rig.inject(0.6, SPU, M.StatusReq())
    rig.run(0.7)
    assert rig.frames(M.StatusAckRange)[-1][1].message.status == RangeStatus.UNRELIABLE   # seed 3.2.11, 6.2
