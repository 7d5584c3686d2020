"""The terminal driver: keys in from a pty, the process's own terminal or a serial port; VT100 out.

Why three kinds of line: the RCP is "a standard RS232C interface" for "a
serial terminal or another VT100-compatible device" (seed 3.2.8, 4.1). On a
host that is a real serial port (pyserial), a pseudo-terminal that a
terminal program such as `screen` or `picocom` opens like a serial device,
or the terminal the simulator runs in.
"""
from __future__ import annotations

import os
import select
import termios
import tty
from collections import deque
from typing import Protocol

from arachnae_proto import messages as M

from console.keymap import label_for_key, message_for_key
from console.screen import Screen


class Port(Protocol):
    def read(self, timeout: float = 0.0) -> bytes:
        """Bytes available now (waiting up to `timeout` s for the first); b"" if none."""

    def write(self, data: bytes) -> None: ...

    def close(self) -> None: ...


class FdPort:
    """A terminal file descriptor (pty side or stdin/stdout), switched to raw mode if it is a tty."""

    def __init__(self, read_fd: int, write_fd: int | None = None, raw: bool = True, owns: tuple[int, ...] = ()) -> None:
        self.rfd, self.wfd = read_fd, read_fd if write_fd is None else write_fd
        self.owns = owns                      # descriptors to close with the port
        self.saved = None
        if raw and os.isatty(self.rfd):       # keys one by one, no echo, no line editing
            self.saved = termios.tcgetattr(self.rfd)
            tty.setraw(self.rfd)

    def read(self, timeout: float = 0.0) -> bytes:
        ready, _, _ = select.select([self.rfd], [], [], timeout)
        if not ready:
            return b""
        try:
            return os.read(self.rfd, 1024)
        except OSError:                       # EIO: the other side of a pty went away
            return b""

    def write(self, data: bytes) -> None:
        view = memoryview(data)
        while view:
            _, ready, _ = select.select([], [self.wfd], [], 1.0)
            if not ready:                     # nobody reads the terminal: drop the picture, keep running
                return
            view = view[os.write(self.wfd, view):]

    def close(self) -> None:
        if self.saved is not None:
            termios.tcsetattr(self.rfd, termios.TCSADRAIN, self.saved)
            self.saved = None
        for fd in self.owns:
            try:
                os.close(fd)
            except OSError:
                pass
        self.owns = ()


class SerialPort:
    """A pyserial port: a real RS-232 port, a pty path, or any `serial_for_url` URL."""

    def __init__(self, url: str, baudrate: int = 9600) -> None:
        import serial                        # pyserial; only needed for this kind of line

        self.ser = serial.serial_for_url(url, baudrate=baudrate, timeout=0)

    def read(self, timeout: float = 0.0) -> bytes:
        self.ser.timeout = timeout
        first = self.ser.read(1)
        if not first:
            return b""
        waiting = self.ser.in_waiting
        return first + (self.ser.read(waiting) if waiting else b"")

    def write(self, data: bytes) -> None:
        self.ser.write(data)
        self.ser.flush()

    def close(self) -> None:
        self.ser.close()


class Console:
    """The RCP console: keys -> queued MOVE / POST_REQ messages; LCD_TEXT / UIC_ALERT -> the screen."""

    def __init__(self, port: Port) -> None:
        self.port = port
        self.screen = Screen()
        self.pending: deque[M.Message] = deque()
        self.sent: list[M.Message] = []      # everything ever handed out by poll(), for logs
        self.peer: str | None = None         # for attach("pty"): the device a terminal program opens
        self.port.write(self.screen.full())

    def poll(self, timeout: float = 0.0) -> list[M.Message]:
        """Read the keys typed so far (waiting up to `timeout` s) and return the messages they make."""
        return self.feed(self.port.read(timeout))

    def feed(self, keys: bytes) -> list[M.Message]:
        """Handle keys already read from the line; return the messages queued so far."""
        for byte in keys:
            key = chr(byte)
            if key == "\x0c":                                    # Ctrl-L: redraw
                self.port.write(self.screen.full())
                continue
            msg = message_for_key(key)
            if msg is None:
                self.port.write(self.screen.status_line(f"? key {key!r}: no command"))
                continue
            self.pending.append(msg)
            self.port.write(self.screen.status_line(f"{label_for_key(key)}: {describe(msg)}"))
        out = list(self.pending)
        self.pending.clear()
        self.sent += out
        return out

    def show_lcd(self, line: int, text: str) -> None:
        """seed 4.1: show one line (0 or 1) of the two-line LCD."""
        self.port.write(self.screen.lcd_line(line, text))

    def show_alert(self, flags: int) -> None:
        self.port.write(self.screen.alert_line(flags))

    def handle(self, msg: M.Message) -> None:
        """A message the MCP sent the UIC/RCP: LCD_TEXT or UIC_ALERT."""
        if isinstance(msg, M.LcdText):
            self.show_lcd(msg.line, msg.text.decode("latin-1"))
        elif isinstance(msg, M.UicAlert):
            self.show_alert(msg.alert)
        else:
            raise TypeError(f"the console shows no {type(msg).__name__}")

    def close(self) -> None:
        self.port.close()


def describe(msg: M.Message) -> str:
    if isinstance(msg, M.Move):
        from arachnae_proto.enums import MovCmd

        return f"MOVE {MovCmd(msg.mov_cmd).name}"
    return msg.NAME


def open_pty() -> tuple[Console, int]:
    """A console running "inside" a new pseudo-terminal; returns it and the master fd (the terminal's side)."""
    import pty

    master, slave = pty.openpty()
    return Console(FdPort(slave, owns=(slave,))), master


def attach(where: str = "pty", baudrate: int = 9600) -> Console:
    """A console for a running simulation.

    where = "stdio": the terminal the process runs in (raw mode; restored by close());
            "pty":   a new pseudo-terminal; connect a terminal program to `console.peer`
                     (e.g. `picocom /dev/pts/7` or `screen /dev/pts/7`);
            anything else: a pyserial URL or device (`/dev/ttyUSB0`, `rfc2217://host:port`, ...).
    """
    if where == "stdio":
        return Console(FdPort(0, 1))
    if where == "pty":
        import pty

        master, slave = pty.openpty()
        tty.setraw(slave)                    # no echo of the picture back as keys until a program sets its mode
        console = Console(FdPort(master, raw=False, owns=(master, slave)))
        console.peer = os.ttyname(slave)
        return console
    return Console(SerialPort(where, baudrate))
