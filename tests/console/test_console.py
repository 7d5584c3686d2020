"""UIC/RCP console (seed 4.1): keymap, VT100 screen bytes, and a real pty end to end."""
from __future__ import annotations

import os
import re
import time

import pytest

from arachnae_proto import messages as M
from arachnae_proto.enums import Alert, MovCmd
from console import KEYMAP, Screen, attach, message_for_key, open_pty
from console.screen import CLEAR_LINE, LCD_COL, LCD_TOP_ROW, goto


def test_keymap_sends_the_seed_commands_as_generated_messages():
    expect = {"F": MovCmd.FORWARD, "B": MovCmd.BACKWARD, "H": MovCmd.STOP,   # seed 4.1
              "L": MovCmd.TURN_LEFT, "R": MovCmd.TURN_RIGHT, "Q": MovCmd.SIDESTEP_LEFT,
              "E": MovCmd.SIDESTEP_RIGHT, "1": MovCmd.TRIPOD, "2": MovCmd.RIPPLE, "3": MovCmd.WAVE}
    for key, cmd in expect.items():
        for k in {key, key.lower()}:
            msg = message_for_key(k)
            assert isinstance(msg, M.Move) and msg.mov_cmd == cmd
            assert M.Move.decode(msg.encode()).mov_cmd == cmd           # valid on the wire
    assert isinstance(message_for_key("p"), M.PostReq)                 # seed 6.3
    assert message_for_key("Z") is None and message_for_key("\r") is None
    # every Mov_Cmd of seed 3.2.3 can be typed
    assert {c for _l, c in KEYMAP.values() if c is not None} == set(MovCmd)


def test_screen_puts_lcd_text_at_its_cursor_positions():
    s = Screen()
    out = s.lcd_line(0, "POST OK").decode("ascii")
    assert goto(LCD_TOP_ROW, LCD_COL) == "\x1b[4;2H"
    assert out.startswith("\x1b[4;2H") and "POST OK         " in out             # padded to 16
    out1 = s.lcd_line(1, "Battery low: 4.3 V, stopping").decode("ascii")
    assert out1.startswith("\x1b[5;2H") and "Battery low: 4.3" in out1 and "V, stopping" not in out1
    full = s.full().decode("ascii")
    assert full.startswith("\x1b[2J")
    # both lines are redrawn at their positions in the full picture
    assert re.search(r"\x1b\[4;2H(\x1b\[7m)?POST OK {9}", full)
    assert re.search(r"\x1b\[5;2H(\x1b\[7m)?Battery low: 4\.3", full)
    status = s.status_line("forward: MOVE FORWARD").decode("ascii")
    assert status == "\x1b[8;1H" + CLEAR_LINE + "> forward: MOVE FORWARD"
    with pytest.raises(ValueError):
        s.lcd_line(2, "x")


def test_alert_rings_the_bell_and_blinks():
    s = Screen()
    out = s.alert_line(Alert.BEEP | Alert.BLINK).decode("ascii")
    assert "BEEP" in out and "BLINK" in out and "\x07" in out and "\x1b[5m" in out
    assert "\x07" not in s.alert_line(Alert.BLINK).decode("ascii")


def read_until(fd: int, pattern: bytes, timeout: float = 2.0) -> bytes:
    data, end = b"", time.monotonic() + timeout
    while pattern not in data and time.monotonic() < end:
        import select

        if select.select([fd], [], [], 0.05)[0]:
            data += os.read(fd, 4096)
    return data


def test_pty_end_to_end_key_in_move_out_lcd_in_vt100_out():
    console, master = open_pty()
    try:
        first = read_until(master, b"UIC/RCP")
        assert b"\x1b[2J" in first                                   # the picture arrived on the terminal
        os.write(master, b"F")                                       # the operator types F
        msgs = console.poll(timeout=2.0)
        assert len(msgs) == 1 and isinstance(msgs[0], M.Move) and msgs[0].mov_cmd == MovCmd.FORWARD
        assert b"MOVE FORWARD" in read_until(master, b"MOVE FORWARD")   # echoed on the status line
        os.write(master, b"hp")
        time.sleep(0.05)
        msgs = console.poll(timeout=1.0)
        msgs += console.poll(timeout=0.2)
        assert [m.NAME for m in msgs] == ["MOVE", "POST_REQ"] and msgs[0].mov_cmd == MovCmd.STOP
        # an LCD_TEXT from the MCP, decoded from its wire bytes, comes out as VT100
        lcd = M.LcdText.decode(M.LcdText(line=1, text="Leg blocked").encode())
        console.handle(lcd)
        out = read_until(master, b"Leg blocked")
        assert b"\x1b[5;2H\x1b[7mLeg blocked     \x1b[0m" in out
    finally:
        console.close()
        os.close(master)


def test_pyserial_port_on_a_pty_device():
    import pty

    master, slave = pty.openpty()
    console = attach(os.ttyname(slave))                             # pyserial opens the device path
    try:
        assert b"UIC/RCP" in read_until(master, b"UIC/RCP")
        os.write(master, b"3")
        msgs = console.poll(timeout=2.0)
        assert [(m.NAME, m.mov_cmd) for m in msgs] == [("MOVE", MovCmd.WAVE)]
        console.show_lcd(0, "Wave gait")
        assert b"\x1b[4;2H\x1b[7mWave gait" in read_until(master, b"Wave gait")
    finally:
        console.close()
        os.close(master)
        os.close(slave)


def test_attach_pty_gives_a_device_a_terminal_program_can_open():
    console = attach("pty")
    try:
        assert console.peer and console.peer.startswith("/dev/")
        fd = os.open(console.peer, os.O_RDWR | os.O_NOCTTY)          # what picocom / screen would do
        try:
            assert b"UIC/RCP" in read_until(fd, b"UIC/RCP")
            os.write(fd, b"B")
            msgs = console.poll(timeout=2.0)
            assert [m.mov_cmd for m in msgs] == [MovCmd.BACKWARD]
            assert console.sent == msgs
        finally:
            os.close(fd)
    finally:
        console.close()
