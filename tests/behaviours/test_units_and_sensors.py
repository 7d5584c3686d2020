"""Sensor controllers (seed 3.2.11-3.2.17): readings quantised into the spec's encodings; TPSC and range sensor rules."""
from __future__ import annotations

from arachnae_proto import messages as M
from arachnae_proto.enums import RangeStatus, TpscContact

from behaviours.units import quantizer
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


def test_usrc_declares_itself_unreliable_after_two_bad_sets(spec):
    rig = Rig(spec, "USRC", 0x27)
    rig.board.sonar = [(d, 0.01) for d in (1.0, 3.0, 1.0, 2.0, 4.0, 1.0)]    # two sets spread far apart
    rig.inject(0.1, SPU, M.DoMeasure())
    rig.inject(0.2, SPU, M.StatusReq())
    rig.run(0.3)
    (_, f), = rig.frames(M.StatusAckRange)
    assert f.message.status == RangeStatus.IN_ORDER          # one bad measurement is not enough
    rig.board.sonar = [(d, 0.01) for d in (1.0, 3.0, 1.0, 2.0, 4.0, 1.0)]
    rig.inject(0.4, SPU, M.DoMeasure())
    rig.inject(0.5, SPU, M.StatusReq())
    rig.run(0.6)
    assert rig.frames(M.StatusAckRange)[-1][1].message.status == RangeStatus.UNRELIABLE   # seed 3.2.11, 6.2
    rig.inject(0.7, SPU, M.XmitData())
    rig.run(0.8)
    (_, f), = rig.frames(M.XmitDataUsrc)
    us = quantizer(M.XmitDataUsrc, "distance")
    assert f.message.distance == round((us.raw(2.0) + us.raw(4.0) + us.raw(1.0)) / 3)   # mean of the last three


def test_jac_drives_its_servo_and_flags_a_stall(spec):
    from behaviours.hardware import ServoState
    rig = Rig(spec, "JAC", 0x45)
    rig.inject(0.1, 0x22, M.JointTarget.from_phys(angle=-45.5, speed=90))
    rig.run(0.2)
    (angle, speed), = rig.board.servo_set
    assert (round(angle, 6), round(speed, 6)) == (round(-45.5 * 3.141592653589793 / 180, 6), round(3.141592653589793 / 2, 6))
    rig.board.servo = ServoState(angle, 0.0, 1.8, 42.0)
    rig.inject(0.3, 0x22, M.JointPoll())
    rig.run(0.4)
    (_, f), = rig.frames(M.JointFeedback)
    fb = f.message.phys()
    assert fb["angle"] == -45.5 and fb["current"] == 1800 and fb["temperature"] == 42
    assert f.message.flags & 0x04 and f.message.flags & 0x08          # STALLED, AT_TARGET (seed 3.2.18 flags)
