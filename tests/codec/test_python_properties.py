"""Properties of the generated Python codec, over every message of the spec."""
from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from arachnae_proto import CodecError, frame
from arachnae_proto.errors import ErrorKind
from arachnae_proto.network import BROADCAST, NODE_ADDRESSES
from arachnae_proto.messages import BY_NAME


def _field_strategy(spec, f):
    if f.type == "enum":
        return st.sampled_from(sorted(f.enum.values.values()))
    if f.type == "flags":
        bits = sorted(f.flags.bits.values())
        return st.sets(st.sampled_from(bits)).map(sum)
    if f.type == "node":
        return st.sampled_from(sorted(n.address for n in spec.nodes))
    lo, hi = f.raw_range
    return st.integers(lo, hi)


def message_strategy(spec, m):
    """Any valid instance of message m, drawn from what the spec allows."""
    fixed = {f.name: _field_strategy(spec, f) for f in m.fields if not f.is_array and f.name != (m.array.count if m.array else None)}
    cls = BY_NAME[m.name]
    if m.array is None:
        return st.fixed_dictionaries(fixed).map(lambda kw: cls(**kw))
    count = m.field(m.array.count)
    lo, hi = count.raw_range
    hi = min(hi, m.array.count_max)
    if m.array.type == "char":
        elems = st.binary(min_size=lo, max_size=hi)
    else:
        elems = st.lists(_field_strategy(spec, m.array), min_size=lo, max_size=hi).map(tuple)
    return st.tuples(st.fixed_dictionaries(fixed), elems).map(lambda t: cls(**t[0], **{m.array.name: t[1]}))


def any_message(spec):
    return st.one_of([message_strategy(spec, m) for m in spec.messages])


def test_encode_then_decode_is_identity(spec) -> None:
    nodes = st.sampled_from(sorted(NODE_ADDRESSES))
    address = nodes | st.just(BROADCAST) | st.integers(0, 255)   # mostly routable, every byte possible

    @settings(max_examples=3000, deadline=None)
    @given(msg=any_message(spec), dst=address, src=address)
    def check(msg, dst, src):
        assert type(msg).decode(msg.encode()) == msg
        data = frame.build(dst, src, msg)
        # seed 3.2.1: from a node, to a node or to broadcast for a broadcast message; otherwise ROUTE
        routable = src in NODE_ADDRESSES and (dst in NODE_ADDRESSES or (dst == BROADCAST and msg.BROADCAST))
        if not routable:
            with pytest.raises(CodecError) as err:
                frame.parse(data)
            assert err.value.kind == ErrorKind.ROUTE
            return
        f = frame.parse(data)
        assert (f.dst, f.src, f.message) == (dst, src, msg)

    check()


@settings(max_examples=3000, deadline=None)
@given(data=st.binary(max_size=300), own=st.none() | st.integers(0, 255))
def test_random_bytes_only_raise_codec_errors(data: bytes, own) -> None:
    try:
        frame.parse(data, own)
    except CodecError:
        pass
    parser = frame.Parser(own)
    for b in data:
        try:
            parser.feed(b)
        except CodecError:
            pass
    try:
        parser.gap()
    except CodecError:
        pass


def test_random_payloads_only_raise_codec_errors(spec) -> None:
    @settings(max_examples=2000, deadline=None)
    @given(name=st.sampled_from(sorted(BY_NAME)), payload=st.binary(max_size=40))
    def check(name, payload):
        try:
            BY_NAME[name].decode(payload)
        except CodecError:
            pass

    check()


@settings(max_examples=500, deadline=None)
@given(data=st.binary(min_size=6, max_size=40), flip=st.integers(0, 39), bit=st.integers(0, 7))
def test_every_single_bit_error_is_detected(data: bytes, flip: int, bit: int) -> None:
    # docs/decisions.md D1: the checksum detects every single-byte error
    good = data[:-2] + frame.crc(data[:-2]).to_bytes(2, "big")
    bad = bytearray(good)
    bad[flip % len(bad)] ^= 1 << bit
    assert frame.crc(bytes(bad[:-2])) != int.from_bytes(bad[-2:], "big")
