"""Live bus monitor: frames off a serial line, decoded by the generated codec, shown as they come.

A tap on one bus (a USB RS-485 adapter, or a pty) delivers bytes. Frames are
delimited as every node of the spec delimits them (seed 3.2.2, nodes.yaml
`idle_gap_chars`): a frame is complete when it holds as many bytes as its
length byte says, and an idle line for the bus's idle gap ends whatever was
started (a partial frame is the codec's TRUNCATED). The codec then decodes each
frame; its CodecError kinds are what the error counts count.

Views: `plain_line` is one tab-separated line per frame (the columns of
trace.tsv); `LiveTable` is a table that rich redraws in place (rate per
message, last value of every field, errors by kind). `--pcapng FILE` writes
each frame through captures.pcapng and flushes it, so a monitor that is
interrupted leaves a capture Wireshark opens.

The --pcapng file is a capture like a simulation's bus.pcapng:
`arachnae trace check FILE` (tracecheck) holds it to the verified protocol,
with `--untimed` when the tap's time stamps are not the line's (a pty, a
buffering USB adapter). Nothing here validates traces.
"""
from __future__ import annotations

import time
from collections import Counter, deque
from dataclasses import dataclass, field
from typing import IO, Any, Callable, Iterator, NamedTuple

from captures.decode import Decoded, decode
from captures.pcapng import CapturedFrame, PcapngWriter, bus_interfaces

RATE_WINDOW_S = 5.0              # rate per message: frames in this many seconds of wall time


class RawFrame(NamedTuple):
    """The bytes of one frame as they came off the line, and when its first byte arrived."""

    time_ns: int                 # wall clock (epoch), so a capture of a real bus dates its frames
    data: bytes


class FrameSplitter:
    """Cuts a byte stream into frames: by the length byte, and by the bus's idle gap (seed 3.2.2)."""

    def __init__(self, spec: Any) -> None:
        self.length_at = spec.frame.header.index("length")   # which header byte counts the payload
        self.header_size, self.overhead = spec.frame.header_size, spec.frame.overhead
        self._buf = bytearray()
        self._start_ns = 0

    def feed(self, chunk: bytes, time_ns: int) -> list[RawFrame]:
        """Bytes that arrived together at `time_ns`; returns the frames they complete."""
        out: list[RawFrame] = []
        for b in chunk:
            if not self._buf:
                self._start_ns = time_ns
            self._buf.append(b)
            if len(self._buf) >= self.header_size and len(self._buf) == self.overhead + self._buf[self.length_at]:
                out.append(RawFrame(self._start_ns, bytes(self._buf)))
                self._buf.clear()
        return out

    def gap(self) -> RawFrame | None:
        """The line was idle for the idle gap: what was started and not complete is a (truncated) frame."""
        if not self._buf:
            return None
        raw = RawFrame(self._start_ns, bytes(self._buf))
        self._buf.clear()
        return raw


# -- what the views show -----------------------------------------------------------------
@dataclass
class MessageStats:
    count: int = 0
    recent: deque = field(default_factory=deque)     # wall times (s) within RATE_WINDOW_S
    route: str = ""                                   # src -> dst of the last one
    fields: str = ""                                  # last value of every field


@dataclass
class MonitorStats:
    """Counts since the monitor started: frames, bytes, per message, errors per codec error kind."""

    started: float = field(default_factory=time.monotonic)
    frames: int = 0
    bytes: int = 0
    messages: dict[str, MessageStats] = field(default_factory=dict)
    errors: Counter = field(default_factory=Counter)
    last_error: dict[str, str] = field(default_factory=dict)

    def add(self, d: Decoded, data: bytes, now: float) -> None:
        self.frames += 1
        self.bytes += len(data)
        if d.message is None:
            self.errors[d.name] += 1
            self.last_error[d.name] = str(d.error)
            return
        st = self.messages.setdefault(d.name, MessageStats())
        st.count += 1
        st.recent.append(now)
        st.route = f"{d.src} -> {d.dst}"
        st.fields = " ".join(f"{f.name}={f.describe(getattr(d.message, f.name))}" for f in d.message.FIELDS)

    def rate(self, name: str, now: float) -> float:
        """Frames per second of one message over the last RATE_WINDOW_S (less at the start)."""
        recent = self.messages[name].recent
        while recent and recent[0] < now - RATE_WINDOW_S:
            recent.popleft()
        window = min(RATE_WINDOW_S, max(now - self.started, 1e-3))
        return len(recent) / window

    def summary(self, now: float) -> list[str]:
        lines = [f"{self.frames} frames, {self.bytes} bytes in {now - self.started:.1f} s"]
        for name, st in sorted(self.messages.items()):
            lines.append(f"  {name}: {st.count}")
        for kind, n in sorted(self.errors.items()):
            lines.append(f"  error {kind}: {n}")
        return lines


def plain_line(raw: RawFrame, d: Decoded, bus: str, t0_ns: int) -> str:
    """time_s, bus, src, dst, message, bytes: trace.tsv's columns for a frame seen on a line."""
    return f"{(raw.time_ns - t0_ns) / 1e9:.6f}\t{bus}\t{d.src}\t{d.dst}\t{d.text}\t{raw.data.hex()}"


class LiveTable:
    """The table rich redraws in place: one row per message, then the errors by kind."""

    def __init__(self, stats: MonitorStats, title: str) -> None:
        self.stats, self.title = stats, title

    def __rich__(self) -> Any:
        from rich.console import Group
        from rich.table import Table

        now = time.monotonic()
        st = self.stats
        msgs = Table(title=f"{self.title}  {st.frames} frames, {st.bytes} bytes, {now - st.started:.0f} s",
                     expand=True, title_justify="left")
        msgs.add_column("message", no_wrap=True)
        msgs.add_column("count", justify="right")
        msgs.add_column("rate/s", justify="right")
        msgs.add_column("last route", no_wrap=True)
        msgs.add_column("last value of each field", overflow="fold")
        for name, m in sorted(st.messages.items()):
            msgs.add_row(name, str(m.count), f"{st.rate(name, now):.1f}", m.route, m.fields)
        errs = Table(title="errors (codec error kinds)", expand=True, title_justify="left")
        errs.add_column("kind", no_wrap=True)
        errs.add_column("count", justify="right")
        errs.add_column("last", overflow="fold")
        for kind, n in sorted(st.errors.items()):
            errs.add_row(kind, str(n), st.last_error[kind])
        return Group(msgs, errs)


# -- the loop ----------------------------------------------------------------------------
def frames_from(port: Any, spec: Any, gap_s: float, stop: Callable[[], bool]) -> Iterator[RawFrame]:
    """Frames off a pyserial port until `stop()`; the read timeout is the bus's idle gap."""
    splitter = FrameSplitter(spec)
    port.timeout = gap_s
    while not stop():
        chunk = port.read(max(1, port.in_waiting))
        if chunk:
            yield from splitter.feed(chunk, time.time_ns())
        else:
            raw = splitter.gap()
            if raw is not None:
                yield raw
    raw = splitter.gap()
    if raw is not None:
        yield raw


class Recorder:
    """Writes each frame to a pcapng file and flushes it (an interrupted monitor leaves a valid file)."""

    def __init__(self, stream: IO[bytes], spec: Any, bus: str) -> None:
        self.stream = stream
        self.writer = PcapngWriter(stream, [i for i in bus_interfaces(spec) if i.name == bus])
        self.bus = bus
        stream.flush()

    def write(self, raw: RawFrame) -> None:
        self.writer.write(CapturedFrame(self.bus, raw.time_ns, raw.data))
        self.stream.flush()
