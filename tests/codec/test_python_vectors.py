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
            out[name] = bytes(items) if info.type == "char" else tuple(items)
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
    # SPEC-NOTES decision 1: the named polynomial's catalogue check value over "123456789"
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
        if kind == "to_milli":
            assert conv.to_phys_milli(int(given)) == int(expected), (name, field, given)
        elif expected == "RANGE":
            with pytest.raises(CodecError) as err:
                conv.to_raw_milli(int(given))
            assert err.value.kind == ErrorKind.RANGE
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
