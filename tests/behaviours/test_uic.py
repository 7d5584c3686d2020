"""UIC/RCP node (seed 3.2.8, 4.1): keys from its RS-232 line -> MOVE / POST_REQ records; LCD and alerts -> VT100."""
from __future__ import annotations

import pytest

from arachnae_proto import messages as M
from arachnae_proto.enums import Alert, BusyStatus, MovCmd
from arachnae_proto.network import ADDRESS_OF

from tests.behaviours.rig import Board, Rig

MCP, UIC = ADDRESS_OF["MCP"], ADDRESS_OF["UIC/RCP"]


@pytest.fixture
def uic(spec, monkeypatch):
    """A UIC/RCP on the bench whose board has an RS-232 line: `rx` holds typed keys, `screen` what it drew."""
    def rcp_write(board: Board, data: bytes) -> None:
        board.__dict__.setdefault("screen", bytearray()).extend(data)

    def rcp_read(board: Board) -> bytes:
        rx = board.__dict__.setdefault("rx", bytearray())
        data = bytes(rx)
        rx.clear()
        return data
    monkeypatch.setattr(Board, "rcp_write", rcp_write, raising=False)
    monkeypatch.setattr(Board, "rcp_read", rcp_read, raising=False)

    def make(grant: bool = True) -> tuple[Rig, bytearray, bytearray]:
        def respond(frame):
            return [(MCP, M.XmitGrant())] if grant and isinstance(frame.message, M.XmitReq) else []
        rig = Rig(spec, "UIC_RCP", UIC, respond)
        b = rig.board
        return rig, b.__dict__.setdefault("rx", bytearray()), b.__dict__["screen"]
    return make


def records(rig: Rig) -> list:
    return [f.message for _t, _bus, f in rig.sent if f.dst == MCP and isinstance(f.message, (M.Move, M.PostReq))]


def test_keys_become_records_through_message_scheduling(uic):
    rig, rx, screen = uic()
    rig.board.after(0.2, rx.extend, b"fL2pZ")
    rig.run(1.0)
    got = [m.mov_cmd if isinstance(m, M.Move) else "POST" for m in records(rig)]
    assert got == [MovCmd.FORWARD, MovCmd.TURN_LEFT, MovCmd.RIPPLE, "POST"]   # seed 4.1, 6.3; Z has no command
    assert len(rig.frames(M.XmitReq, MCP)) == 4                                # seed 3.2.2: one request per record
    text = bytes(screen)
    assert b"> forward: MOVE FORWARD" in text and b"> POST: POST_REQ" in text
    assert b"? key 'Z': no command" in text
    assert rig.node.debug_metrics()["commands"] == {"MOVE FORWARD": 1, "MOVE RIPPLE": 1, "MOVE TURN_LEFT": 1,
                                                    "POST_REQ": 1}


def test_busy_while_a_command_waits_for_the_bus(uic):
    rig, rx, _screen = uic(grant=False)
    rig.board.after(0.1, rx.extend, b"H")
    rig.inject(0.5, MCP, M.StatusReq())
    rig.run(0.6)
    assert rig.frames(M.StatusAckBusy, MCP)[-1][1].message.status == BusyStatus.BUSY
    rig.inject(0.7, MCP, M.XmitGrant())
    rig.inject(0.8, MCP, M.StatusReq())
    rig.run(0.9)
    assert [m.mov_cmd for m in records(rig)] == [MovCmd.STOP]
    assert rig.frames(M.StatusAckBusy, MCP)[-1][1].message.status == BusyStatus.NOT_BUSY
    rig.inject(1.0, MCP, M.XmitGrant())              # a repeated grant: the MOVE did not get through
    rig.run(1.1)
    assert [m.mov_cmd for m in records(rig)] == [MovCmd.STOP, MovCmd.STOP]


def test_lcd_text_and_alerts_are_drawn_on_the_terminal(uic):
    rig, _rx, screen = uic()
    rig.inject(0.1, MCP, M.LcdText(line=1, text=b"Leg blocked"))
    rig.inject(0.2, MCP, M.UicAlert(alert=int(Alert.BEEP | Alert.BLINK)))
    rig.run(0.5)
    text = bytes(screen)
    assert b"\x1b[5;2H\x1b[7mLeg blocked     \x1b[0m" in text           # LCD line 1, 16 characters
    assert b"\x07" in text and b"\x1b[5m! BEEP BLINK" in text           # bell + blinking indicator
    assert rig.node.debug_metrics()["lcd"] == ["", "Leg blocked"]
    rx_before = len(text)
    rig.node.key("\x0c")                                               # Ctrl-L redraws the whole picture
    assert bytes(screen)[rx_before:].startswith(b"\x1b[2J") and b"Leg blocked" in bytes(screen)[rx_before:]
