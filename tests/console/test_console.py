"""UIC/RCP console (seed 4.1): keymap, VT100 screen bytes, the host's terminal lines."""
from __future__ import annotations

import os
import re
import select
import time

import pytest

from arachnae_proto import messages as M
from arachnae_proto.enums import Alert, MovCmd
from console import KEYMAP, Screen, message_for_key
from behaviours.rcp_screen import CLEAR_LINE, LCD_COL, LCD_TOP_ROW, goto
from console.terminal import attach, open_pty


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
        if select.select([fd], [], [], 0.05)[0]:
            data += os.read(fd, 4096)
    return data


def test_pty_line_carries_keys_in_and_vt100_out():
    port, term = open_pty()
    try:
        port.write(Screen().full())
        assert b"UIC/RCP" in read_until(term, b"UIC/RCP")              # the picture reached the terminal
        os.write(term, b"Fh")                                         # the operator types
        assert port.read(timeout=2.0) + port.read(timeout=0.1) == b"Fh"
    finally:
        port.close()
        os.close(term)


def test_pyserial_port_on_a_pty_device():
    import pty

    master, slave = pty.openpty()
    port = attach("serial:" + os.ttyname(slave))                      # pyserial opens the device path
    try:
        port.write(b"\x1b[4;2HWave gait")
        assert b"Wave gait" in read_until(master, b"Wave gait")
        os.write(master, b"3")
        assert port.read(timeout=2.0) == b"3"
    finally:
        port.close()
        os.close(master)
        os.close(slave)


def test_attach_pty_gives_a_device_a_terminal_program_can_open():
    port = attach("pty")
    try:
        assert port.peer and port.peer.startswith("/dev/")
        fd = os.open(port.peer, os.O_RDWR | os.O_NOCTTY)              # what picocom / screen would do
        try:
            port.write(b"ARACHNAE II  UIC/RCP")
            assert b"UIC/RCP" in read_until(fd, b"UIC/RCP")
            os.write(fd, b"B")
            assert port.read(timeout=2.0) == b"B"
        finally:
            os.close(fd)
    finally:
        port.close()


def test_a_terminal_nobody_reads_does_not_stall_the_writer():
    port, term = open_pty()
    try:
        t0 = time.monotonic()
        for _ in range(200):                                          # far more than the pty buffers
            port.write(b"x" * 1024)
        assert time.monotonic() - t0 < 3 * port.write_timeout + 1.0
        assert port.stalled
        assert b"xxxx" in read_until(term, b"xxxx")                   # what fitted is there
    finally:
        port.close()
        os.close(term)


def test_the_firmware_side_does_not_pull_in_the_host_terminal():
    import subprocess
    import sys

    code = "import sys, behaviours.level0; print('console.terminal' in sys.modules, 'termios' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["False", "False"]


def _line_of(fd: int) -> tuple[int, int, bool, bool, bool]:
    """(speed, CSIZE bits, parity on, odd parity, two stop bits) as termios reports the device."""
    import termios

    attrs = termios.tcgetattr(fd)
    c = attrs[2]
    return attrs[5], c & termios.CSIZE, bool(c & termios.PARENB), bool(c & termios.PARODD), bool(c & termios.CSTOPB)


def _expect(line) -> tuple[int, int, bool, bool, bool]:
    import termios

    return (getattr(termios, f"B{line.baud}"), getattr(termios, f"CS{line.data_bits}"), line.parity != "none",
            line.parity in ("odd", "mark"), line.stop_bits > 1)


def test_both_kinds_of_line_take_the_spec_rcp_settings():
    """seed 4.1: the RCP line's baud, bits, parity and stop bits are the spec's (nodes.yaml lines.rcp), on the
    pty a terminal program opens and on a pyserial port; another line's settings are applied as given."""
    import pty

    from arachnae_proto.network import LINES, SerialLine
    from console.terminal import set_line

    port = attach("pty")
    try:
        fd = os.open(port.peer, os.O_RDWR | os.O_NOCTTY)
        try:
            assert _line_of(fd) == _expect(LINES["rcp"])
        finally:
            os.close(fd)
    finally:
        port.close()
    master, slave = pty.openpty()
    other = SerialLine("test", "UIC/RCP", 19200, 8, "none", 2, "4.1")   # a Linux pty keeps speed and stop bits only
    try:
        set_line(slave, other)
        assert _line_of(slave) == _expect(other) != _expect(LINES["rcp"])
        serial_port = attach("serial:" + os.ttyname(slave))
        try:
            assert _line_of(slave) == _expect(LINES["rcp"])
        finally:
            serial_port.close()
        with pytest.raises(ValueError, match="12345 baud"):
            set_line(slave, other._replace(baud=12345))
    finally:
        os.close(master)
        os.close(slave)
