"""The terminal line on the host: keys in from a pty, the process's own terminal or a serial port; bytes out.

Why three kinds of line: the RCP is "a standard RS232C interface" for "a
serial terminal or another VT100-compatible device" (seed 3.2.8, 4.1). On a
host that is a real serial port (pyserial), a pseudo-terminal that a
terminal program such as `screen` or `picocom` opens like a serial device,
or the terminal the simulator runs in. The line decides nothing: the
UIC/RCP node (behaviours.level0) reads the keys and writes the picture.
"""
from __future__ import annotations

import os
import select
import termios
import tty
from typing import Protocol

from arachnae_proto.network import LINES, SerialLine

# seed 4.1: the RCP's RS-232C line; its settings are the spec's (nodes.yaml lines.rcp), never restated here
RCP_LINE = LINES["rcp"]
_PARITY = {"none": "N", "even": "E", "odd": "O", "mark": "M", "space": "S"}   # pyserial's parity letters


class Port(Protocol):
    peer: str | None

    def read(self, timeout: float = 0.0) -> bytes:
        """Bytes available now (waiting up to `timeout` s for the first); b"" if none."""

    def write(self, data: bytes) -> None: ...

    def close(self) -> None: ...


class FdPort:
    """A terminal file descriptor (pty side or stdin/stdout), switched to raw mode if it is a tty."""

    def __init__(self, read_fd: int, write_fd: int | None = None, raw: bool = True, owns: tuple[int, ...] = (),
                 write_timeout: float = 1.0) -> None:
        self.rfd, self.wfd = read_fd, read_fd if write_fd is None else write_fd
        self.owns = owns                      # descriptors to close with the port
        self.write_timeout = write_timeout
        self.stalled = False
        self.peer: str | None = None          # the device a terminal program opens (pty)
        self.saved = None
        if raw and os.isatty(self.rfd):       # keys one by one, no echo, no line editing
            self.saved = termios.tcgetattr(self.rfd)
            tty.setraw(self.rfd)

    def read(self, timeout: float = 0.0) -> bytes:
        ready, _, _ = select.select([self.rfd], [], [], max(0.0, timeout))
        if not ready:
            return b""
        try:
            return os.read(self.rfd, 1024)
        except OSError:                       # EIO: the other side of a pty went away
            return b""

    def write(self, data: bytes) -> None:
        """Write all of `data`, unless the terminal stops reading: then drop the rest and keep running
        (after one timed-out write the next ones do not wait until the terminal reads again)."""
        view = memoryview(data)
        wait = 0.0 if self.stalled else self.write_timeout
        while view:
            _, ready, _ = select.select([], [self.wfd], [], wait)
            try:
                if not ready:
                    raise BlockingIOError
                view = view[os.write(self.wfd, view):]
            except BlockingIOError:           # nobody reads the terminal: drop the picture
                self.stalled = True
                return
        self.stalled = False

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

    def __init__(self, url: str, line: SerialLine = RCP_LINE) -> None:
        import serial                        # pyserial; only needed for this kind of line

        self.ser = serial.serial_for_url(url, baudrate=line.baud, bytesize=line.data_bits,
                                         parity=_PARITY[line.parity], stopbits=line.stop_bits, timeout=0)
        self.peer: str | None = url

    def read(self, timeout: float = 0.0) -> bytes:
        self.ser.timeout = max(0.0, timeout)
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


def set_line(fd: int, line: SerialLine) -> None:
    """Give a tty the line's speed and character framing (a pty only records them; a real port uses them)."""
    speed = getattr(termios, f"B{line.baud}", None)
    if speed is None:
        raise ValueError(f"spec lines: {line.baud} baud is no termios speed")
    attrs = termios.tcgetattr(fd)
    cflag = attrs[2] & ~(termios.CSIZE | termios.PARENB | termios.PARODD | termios.CSTOPB)
    cflag |= getattr(termios, f"CS{line.data_bits}")
    if line.parity != "none":
        cflag |= termios.PARENB | (termios.PARODD if line.parity in ("odd", "mark") else 0)
    if line.stop_bits > 1:
        cflag |= termios.CSTOPB
    attrs[2], attrs[4], attrs[5] = cflag, speed, speed
    termios.tcsetattr(fd, termios.TCSANOW, attrs)


def open_pty() -> tuple[FdPort, int]:
    """A line whose far end is a new pseudo-terminal; returns it and the fd of the terminal's side."""
    import pty

    master, slave = pty.openpty()
    tty.setraw(slave)                        # the terminal side: no echo, no line editing
    set_line(slave, RCP_LINE)                # what `stty -F` shows a terminal program: the spec's line
    os.set_blocking(master, False)           # a full pty buffer must not block the simulation
    port = FdPort(master, raw=False, owns=(master,), write_timeout=0.1)
    port.peer = os.ttyname(slave)
    return port, slave


def attach(where: str = "pty", line: SerialLine = RCP_LINE) -> Port:
    """The RCP line for a running simulation.

    where = "stdio": the terminal the process runs in (raw mode; restored by close());
            "pty":   a new pseudo-terminal; connect a terminal program to `port.peer`
                     (e.g. `picocom /dev/pts/7` or `screen /dev/pts/7`);
            "serial:DEVICE" or anything else: a pyserial device or URL (`/dev/ttyUSB0`, `rfc2217://host:port`).
    """
    if where == "stdio":
        return FdPort(0, 1)
    if where == "pty":
        port, slave = open_pty()
        port.owns = port.owns + (slave,)    # keep the device open while nobody has it open yet
        return port
    return SerialPort(where.removeprefix("serial:"), line)
