"""The generated Python codec against the shared vectors (the C codec reads the same file)."""
from __future__ import annotations

import pytest

from arachnae_proto import CodecError, ErrorKind, frame
from arachnae_proto.messages import BY_NAME


def _expected_fields(message_cls, tokens: list[str]) -> dict:
    out = {}
    for tok in tokens:
        name, value = tok.split("=")
        if name == message_cls.ARRAY:
            items = [] if value == "-" else [int(x) for x in value.split(":")]
            info = next(f for f in message_cls.FIELDS if f.name == name)
            out[name] = bytes(items) if info.type == "char" and all(0 <= b <= 255 for b in items) else tuple(items)
        else:
            out[name] = int(value)
    return out


def _lines(vectors, kind):
    return [v for v in vectors if v[0] == kind]


def test_vectors_cover_every_message(vectors, spec):
    named = {v[1] for v in _lines(vectors, "msg")}
    assert named == {m.name for m in spec.messages}


def test_crc_lines(vectors):
    lines = _lines(vectors, "crc")
    assert any(v[1] == b"123456789".hex() for v in lines)
    for _, data, value in lines:
        assert frame.crc(b"" if data == "-" else bytes.fromhex(data)) == int(value, 16)


def test_checksum_catalogue_check_value(spec):
    # docs/decisions.md D1: the named polynomial's catalogue check value over "123456789"
    assert frame.crc(b"123456789") == spec.frame.checksum.check == 0x29B1


def test_messages_decode_and_reencode_byte_for_byte(vectors):
    lines = _lines(vectors, "msg")
    assert len(lines) > 100
    for _, name, case, hex_frame, *fields in lines:
        data = bytes.fromhex(hex_frame)
        f = frame.parse(data)
        cls = BY_NAME[name]
        assert type(f.message) is cls, case
        assert f.message.to_dict() == _expected_fields(cls, fields), f"{name} {case}"
        assert frame.build(f.dst, f.src, cls(**f.message.to_dict())) == data, f"{name} {case}"


def test_conversions(vectors):
    for kind, name, field, given, expected in _lines(vectors, "to_raw") + _lines(vectors, "to_milli"):
        conv = next(f for f in BY_NAME[name].FIELDS if f.name == field).conv
        convert = conv.to_phys_milli if kind == "to_milli" else conv.to_raw_milli
        if expected == "RANGE":
            with pytest.raises(CodecError) as err:
                convert(int(given))
            assert err.value.kind == ErrorKind.RANGE, (kind, name, field, given)
        elif kind == "to_milli":
            assert conv.to_phys_milli(int(given)) == int(expected), (name, field, given)
        else:
            assert conv.to_raw_milli(int(given)) == int(expected), (name, field, given)


@pytest.mark.parametrize("mode", ["whole", "stream"])
def test_bad_frames(vectors, mode):
    lines = _lines(vectors, "bad")
    kinds = {v[4] for v in lines}
    assert kinds >= {"TRUNCATED", "OVERSIZE", "CHECKSUM", "ADDRESS", "OPCODE", "LENGTH", "RANGE"}
    for _, case, own, hex_frame, expected in lines:
        data = b"" if hex_frame == "-" else bytes.fromhex(hex_frame)
        if mode == "stream" and not data:
            continue  # silence on a line is no frame, not an error
        own_addr = None if own == "-" else int(own, 16)
        with pytest.raises(CodecError) as err:
            if mode == "whole":
                frame.parse(data, own_addr)
            else:
                parser = frame.Parser(own_addr)
                for b in data:
                    parser.feed(b)
                parser.gap()
        assert err.value.kind.name == expected, case


def test_refused_values(vectors):
    """Encode-side vectors: values the C codec refuses too (tests/c/vectors_test.c reads the same lines)."""
    lines = _lines(vectors, "refuse")
    assert len(lines) > 300
    for _, name, case, expected, *fields in lines:
        cls = BY_NAME[name]
        values = _expected_fields(cls, fields)
        assert set(values) == {f.name for f in cls.FIELDS}, case
        with pytest.raises(CodecError) as err:
            cls(**values).encode()
        assert err.value.kind.name == expected, f"{name} {case}: {err.value}"
        assert str(err.value).startswith(f"{name}."), f"{name} {case}: {err.value}"


def test_refuse_vectors_cover_every_field(vectors, spec):
    """Every field of every message has at least one value encoders must refuse, and every range,
    enum gap and reserved flag bit its boundary cases."""
    cases = {(v[1], v[2]) for v in _lines(vectors, "refuse")}
    for m in spec.messages:
        for f in m.fields:
            assert any(n == m.name and c.startswith(f"{f.name}_") for n, c in cases), (m.name, f.name)
            lim_lo, lim_hi = f.raw_limits
            want = {"below_bits", "above_bits"}
            if f.type in ("uint", "int") and not f.is_array and f.name != (m.array.count if m.array else None):
                lo, hi = f.raw_range
                want |= {"below_range"} if lo > lim_lo else set()
                want |= {"above_range"} if hi < lim_hi else set()
            if f.type == "enum":
                values = set(f.enum.values.values())
                want |= {f"gap_{v}" for v in range(lim_lo, lim_hi + 1)
                         if v not in values and (v - 1 in values or v + 1 in values or v in (lim_lo, lim_hi))}
            if f.type == "flags":
                want |= {f"reserved_bit{k}" for k in range(f.bits) if not f.flags.mask >> k & 1}
            if m.array is not None and f.name == m.array.count:
                want = {"above_range", "above_bits"} | ({"below_range"} if f.raw_range[0] > 0 else set())
            missing = {w for w in want if (m.name, f"{f.name}_{w}") not in cases}
            assert not missing, (m.name, f.name, missing)
