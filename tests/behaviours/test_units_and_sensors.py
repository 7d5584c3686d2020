"""Sensor controllers (seed 3.2.11-3.2.17): readings quantised into the spec's encodings; TPSC and range sensor rules.

The JAC is tested in test_jac.py."""
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


def test_a_request_never_starts_on_its_backoff_slots_closing_edge(spec):
    """spec address_backoff: after a corrupt frame a slave starts only inside its own slot of the window. One
    begun in the slot's last bit time meets the next rank's start and reads as the next slot in the trace
    (frame_loss seed 7 on ec5018d: the SPU's XMIT_REQ exactly one slot after the corrupt frame, backoff_slot)."""
    from behaviours.runtime import BusTiming

    rig = Rig(spec, "TPSC", 0x28)                             # spec priority [TPSC, IRRC]: rank 0 on the sensor bus
    node, t = rig.node, BusTiming("sensor")
    assert node.rank("sensor") == 0
    rig.run(0.5)
    node.on_line_frame("sensor", b"\x04\x20\x46\x00\x00\x0c")  # a collision's garbage ends now: the window opens
    end = 0.5 + len(node.net.requesters["sensor"]) * node.net.backoff_slots * t.slot_s
    rig.run(0.5 + t.slot_s / 2)
    assert node._backoff_wait("sensor") == 0.0                # inside slot 0: go
    rig.run(0.5 + t.slot_s - t.bit_s / 2)
    assert abs(node._backoff_wait("sensor") - (end - rig.board.t)) < 1e-9   # its closing edge: wait for the end
