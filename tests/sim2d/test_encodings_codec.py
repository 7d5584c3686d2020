from __future__ import annotations

from hypothesis import given, settings, strategies as st

from sim2d import encodings as enc
from sim2d.codec import Codec


def test_seed_tables(spec):
    enc.use_spec(spec)
    # seed 3.2.16 table
    assert [enc.lsc_light(x) for x in (0.1, 1, 10, 100, 1000)] == [0, 64, 128, 192, 255]
    assert enc.lsc_light(0.01) == 0 and enc.lsc_light(1e6) == 255
    # seed 3.2.15 table: -20 -> 11101100, 0 -> 0, 100 -> 01100100
    assert [enc.tsc_temperature(c) & 0xFF for c in (-20, 0, 100)] == [0b11101100, 0, 0b01100100]
    assert enc.tsc_temperature(150) == 100
    # seed 3.2.11 / 3.2.13: 0..255 = 0..10 m / 0..10 cm
    assert enc.usrc_distance(0) == 0 and enc.usrc_distance(10) == 255 and enc.usrc_distance(25) == 255
    assert enc.usrc_distance(5) in (127, 128)
    assert enc.irrc_distance(0.10) == 255 and enc.irrc_distance(0.05) in (127, 128)
    # seed 3.2.14: -60..60, +-3 degree resolution
    assert enc.isc_inclination(10.4) == 9 and enc.isc_inclination(-80) == -60
    # seed 3.2.12 flag bits
    assert (enc.tpsc_whiskers(True, False), enc.tpsc_whiskers(False, True), enc.tpsc_whiskers(True, True),
            enc.tpsc_whiskers(False, False)) == (0x10, 0x20, 0x40, 0)
    # seed 3.2.17 window 4.2..5.0 V, clamped
    assert enc.psc_voltage(3.0) == enc.psc_voltage(4.2) < enc.psc_voltage(4.6) < enc.psc_voltage(5.0) == enc.psc_voltage(9)


def test_codec_round_trip_and_range_check(spec):
    c = Codec(spec)
    f = c.encode("XMIT_DATA_ISC", 0x04, 0x2A, longitudinal=-9, transverse=3)
    d = c.decode(f)
    assert (d.dst, d.src, d.name, d.fields) == (0x04, 0x2A, "XMIT_DATA_ISC", {"longitudinal": -9, "transverse": 3})
    f = c.encode("POST_REPORT", 1, 3, missing_count=2, missing=bytes([0x21, 0x41]))
    assert c.decode(f).fields["missing"] == bytes([0x21, 0x41])
    try:
        c.encode("XMIT_DATA_ISC", 4, 0x2A, longitudinal=61, transverse=0)
    except ValueError:
        pass
    else:
        raise AssertionError("out-of-range field accepted")


@settings(max_examples=200, deadline=None)
@given(pos=st.integers(0, 6), flip=st.integers(1, 255), angle=st.integers(0, 359), dist=st.integers(0, 255))
def test_any_single_byte_error_is_rejected(spec, pos, flip, angle, dist):
    c = Codec(spec)
    f = bytearray(c.encode("XMIT_DATA_USRC", 0x04, 0x27, distance=dist, angle=angle))
    pos %= len(f)
    f[pos] ^= flip
    assert c.decode(bytes(f)) is None
