"""Generated Python node skeletons: typed dispatch and the common INIT/ID_REQ/STATUS_REQ replies."""
from __future__ import annotations

import pytest

from arachnae_proto import frame
from arachnae_proto import messages as M
from arachnae_proto.skeletons import skeleton_class


def _node(spec, short):
    sent = []
    node = spec.node(short)
    obj = skeleton_class(node.role)(node.address, lambda bus, data: sent.append((bus, data)))
    return obj, sent


def test_each_role_dispatches_exactly_what_it_receives(spec) -> None:
    for role in spec.roles:
        cls = skeleton_class(role)
        assert {c.NAME for c in cls.RECEIVES} == {m.name for m in spec.receives(role)}, role
        assert {c.NAME for c in cls.SENDS} == {m.name for m in spec.sends(role)}, role


def test_id_req_is_answered_with_own_address_on_the_shared_bus(spec) -> None:
    tpsc, sent = _node(spec, "TPSC")
    spu = spec.node("SPU")
    tpsc.receive("sensor", frame.build(tpsc.address, spu.address, M.IdReq()))
    assert len(sent) == 1
    bus, data = sent[0]
    reply = frame.parse(data)
    assert bus == "sensor" and (reply.dst, reply.src) == (spu.address, tpsc.address)
    assert reply.message == M.IdAck(address=tpsc.address)  # seed 3.2.2


def test_status_req_uses_the_roles_status_layout(spec) -> None:
    mmc, sent = _node(spec, "MMC")
    mmc.receive("first", frame.build(mmc.address, spec.node("MCP").address, M.StatusReq()))
    assert type(frame.parse(sent[0][1]).message) is M.StatusAckMmc  # seed 3.2.4
    jac, sent = _node(spec, "JAC(2,3)")
    jac.receive("joints2", frame.build(jac.address, spec.node("LCP(2)").address, M.StatusReq()))
    assert frame.parse(sent[0][1]).message == M.StatusAckOrder(status=0)


def test_hooks_receive_typed_messages_and_foreign_frames_are_ignored(spec) -> None:
    seen = []
    cls = skeleton_class("MMC")

    class Behaviour(cls):
        def on_move_relayed(self, src, msg):
            seen.append((src, msg))

    mmc = Behaviour(spec.node("MMC").address, lambda bus, data: None)
    move = M.MoveRelayed(address=spec.node("NP3").address, mov_cmd=1)
    mmc.receive("first", frame.build(mmc.address, spec.node("MCP").address, move))
    mmc.receive("first", frame.build(spec.node("SPU").address, spec.node("MCP").address, move))
    assert seen == [(spec.node("MCP").address, move)]


def test_send_refuses_a_message_the_role_does_not_send_and_cross_layer_routes(spec) -> None:
    tpsc, _ = _node(spec, "TPSC")
    with pytest.raises(ValueError, match="does not send"):
        tpsc.send(spec.node("SPU").address, M.Move(mov_cmd=1))
    with pytest.raises(ValueError, match="shares no bus"):
        tpsc.send(spec.node("MCP").address, M.IdAck(address=tpsc.address))  # docs/decisions.md D2


def test_init_calls_reset(spec) -> None:
    calls = []
    cls = skeleton_class("NP3")

    class Behaviour(cls):
        def reset(self):
            calls.append(True)

    np3 = Behaviour(spec.node("NP3").address, lambda bus, data: None)
    np3.receive("first", frame.build(0xFF, spec.node("MCP").address, M.Init()))  # seed 3.2.3: broadcast INIT
    assert calls == [True]


def test_unhandled_and_unexpected_messages_are_counted_and_noted(spec) -> None:
    """Issue 10 item 10: the default hooks record what they drop (a counter and a trace note)."""
    rlc, sent = _node(spec, "RLC")
    mcp = spec.node("MCP").address
    rlc.receive("first", frame.build(rlc.address, mcp, M.XmitGrant()))          # RLC receives it, nothing handles it
    rlc.receive("first", frame.build(rlc.address, mcp, M.XmitGrant()))
    rlc.receive("first", frame.build(rlc.address, mcp, M.JointPoll()))          # not for an RLC per the spec
    assert rlc.unhandled == {"XMIT_GRANT": 2} and rlc.unexpected == {"JOINT_POLL": 1}
    assert list(rlc.notes) == [("unhandled", {"message": "XMIT_GRANT", "src": mcp})] * 2 + \
        [("unexpected", {"message": "JOINT_POLL", "src": mcp})]
    assert sent == []
    for _ in range(100):
        rlc.receive("first", frame.build(rlc.address, mcp, M.XmitGrant()))
    assert rlc.unhandled["XMIT_GRANT"] == 102 and len(rlc.notes) < 100   # the trace is bounded, the count is not


def test_frames_no_node_could_send_are_codec_errors_not_foreign_frames(spec) -> None:
    """seed 3.2.1: a frame for us from an address that is no node, or a non-broadcast message to broadcast, is
    reported (ROUTE) to on_codec_error; a frame for another node is ignored (ADDRESS)."""
    errors = []
    cls = skeleton_class("MMC")

    class Behaviour(cls):
        def on_codec_error(self, bus, err):
            errors.append(err.kind.name)

    mmc = Behaviour(spec.node("MMC").address, lambda bus, data: None)
    mcp = spec.node("MCP").address
    stranger = next(a for a in range(256) if a not in {n.address for n in spec.nodes} and a != spec.broadcast)
    move = M.MoveRelayed(address=spec.node("NP3").address, mov_cmd=1)
    assert mmc.receive("first", frame.build(mmc.address, stranger, move)) is None
    assert mmc.receive("first", frame.build(spec.broadcast, mcp, move)) is None     # MOVE_RELAYED is not broadcast
    assert mmc.receive("first", frame.build(spec.node("SPU").address, stranger, move)) is None   # not ours
    assert errors == ["ROUTE", "ROUTE"]
