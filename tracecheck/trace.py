"""The bus trace as a file: trace.tsv columns, debug-port rows, and the reader.

One row per frame on a wire (times, bus, sending station, the codec's reading,
the bytes heard, flags, the bytes sent) plus rows from the nodes' debug ports
that the protocol rules need (bus column `debug`), e.g. the MCP's POST verdict.
A capture from hardware may leave `sender`, `flags` and `sent` empty: the
validator then works from the bytes heard and the frames' times alone. A pcapng
capture (a run's bus.pcapng, `arachnae monitor --pcapng`) reads the same way
(`from_capture`): its interfaces are buses, a frame ends when its bytes have
left the line at the bus's baud rate, and it has no debug-port rows.
"""
from __future__ import annotations

import functools
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Iterable

from arachnae.errors import UserError, located
from arachnae_proto import CodecError
from arachnae_proto.frame import Frame as Parsed, check, parse

from captures.decode import decode

COLUMNS = ("start_s", "end_s", "bus", "sender", "src", "dst", "message", "bytes", "flags", "sent")
DEBUG_BUS = "debug"
# debug-port events the validator needs, as written by the nodes (behaviours' hw.note): the MCP's POST verdict
# and the reflex source raising a reflex request (the line shows only when the request got on it)
PROTOCOL_NOTES = ("post_verdict", "reflex_raised")
LIST_SEP = ";"           # between names in a debug row (node names contain commas)


@dataclass
class TraceFrame:
    """One frame on one bus, as the validator sees it."""

    line: int                      # line in trace.tsv (1 = header)
    start: float
    end: float
    bus: str
    sender: str                    # station that drove the line ('' when unknown)
    sent: bytes                    # bytes the sender put on the line
    heard: bytes | None            # what the receivers got (None: lost)
    flags: tuple[str, ...] = ()
    parsed: Parsed | None = None   # the sent frame as the codec reads it (None: not a frame)
    intact: bool = False           # the bytes heard pass the codec's checks

    @property
    def name(self) -> str:
        return self.parsed.message.NAME if self.parsed is not None else "?"

    @property
    def lost(self) -> bool:
        return self.heard is None


@dataclass
class TraceNote:
    line: int
    t: float
    node: str
    event: str
    fields: dict[str, str] = field(default_factory=dict)


@dataclass
class Trace:
    path: str
    frames: list[TraceFrame]
    notes: list[TraceNote]


def note_message(event: str, **fields: object) -> str:
    """The message column of a debug row: `event key=value ...` (values without blanks)."""
    return " ".join([event] + [f"{k}={str(v).replace(' ', '_')}" for k, v in fields.items()])


def note_row(t: float, node: str, event: str, data: dict) -> str | None:
    """A debug-port note as a trace row, when the protocol rules need it. `at` in a note's data is when the
    node did it, if the simulator learnt of it later (a SIL node's notes arrive up to a sync period late)."""
    if event == "post_verdict":
        v = data["verdict"]
        text = note_message(event, verdict=v.verdict, missing=LIST_SEP.join(v.missing) or "-")
    elif event == "reflex_raised":
        text = note_message(event, reflex=data["reflex"])
    else:
        return None
    t = float(data.get("at", t))
    return "\t".join((f"{t:.6f}", f"{t:.6f}", DEBUG_BUS, node, "-", "-", text, "", "", ""))


def frame_row(start: float, end: float, bus: str, sender: str, sent: bytes, heard: bytes | None,
              flags: tuple[str, ...]) -> str:
    """A frame as a trace row; the message column is the generated codec's reading of the bytes heard."""
    data = heard if heard is not None else sent
    return f"{start:.6f}\t{end:.6f}\t{bus}\t{sender}\t{_reading(data)}\t{','.join(flags)}\t{sent.hex()}"


@functools.lru_cache(maxsize=1 << 16)
def _reading(data: bytes) -> str:
    """The src, dst, message and bytes columns of a frame: the same bytes always read the same, and a run
    repeats most of its frames (polls, set-points: ~2,500 distinct among ~19,000 in the default run)."""
    d = decode(data)
    return f"{d.src}\t{d.dst}\t{d.text}\t{data.hex()}"


def trace_lines(frames: Iterable[Any], notes: Iterable[tuple[float, str, str, dict[str, Any]]] = ()) -> list[str]:
    """trace.tsv's rows for a run's frames (sim2d.bus.TraceEntry: start, end, bus, sender, sent, heard, flags)
    in the order they ended, with the debug-port notes the protocol rules need (PROTOCOL_NOTES) as `debug`
    rows at their time. The message column is the generated codec's reading of the bytes heard
    (captures.decode); a frame it rejects shows the codec's reason."""
    rows = [(f.end, 1, frame_row(f.start, f.end, f.bus, f.sender, f.sent, f.heard, f.flags)) for f in frames]
    rows += [(float(data.get("at", t)), 0, row) for t, node, event, data in notes
             if (row := note_row(t, node, event, data)) is not None]
    rows.sort(key=lambda r: (r[0], r[1]))
    return [row for _t, _k, row in rows]


@functools.lru_cache(maxsize=1 << 16)      # a trace repeats most of its frames (_reading); the validator only reads
def _parse_or_none(data: bytes) -> Parsed | None:
    try:
        return parse(data)
    except CodecError:
        return None


@functools.lru_cache(maxsize=1 << 16)
def _intact(data: bytes | None) -> bool:
    if data is None:
        return False
    try:
        check(data)
        return True
    except CodecError:
        return False


PCAPNG_MAGIC = bytes.fromhex("0a0d0d0a")      # a pcapng file starts with a section header block


def from_capture(capture: Any, spec: Any, shown: str) -> Trace:
    """A pcapng capture's frames as a trace: times from its first frame, ends at the spec's baud rate.

    `line` is the frame's number in the capture (1 = the first), so a violation names it."""
    t0 = min((f.time_ns for f in capture.frames), default=0)
    frames = []
    for no, c in enumerate(capture.frames, start=1):
        b = spec.buses.get(c.bus)
        if b is None:
            raise UserError(located(shown, None, f"frame {no}: interface {c.bus!r} is not a bus of the spec "
                                                 f"({', '.join(spec.buses)})"))
        start = (c.time_ns - t0) * 1e-9
        end = start + b.frame_time_us(len(c.data)) * 1e-6
        heard = None if "lost" in c.flags else c.data
        sent = c.sent if c.sent is not None else c.data
        frames.append(TraceFrame(no, start, end, c.bus, c.sender, sent, heard, tuple(c.flags), _parse_or_none(sent),
                                 _intact(heard)))
    # the tap's order where times tie (a tap reading a buffer of frames at once stamps them alike)
    frames.sort(key=lambda f: (f.start, f.line))
    return Trace(shown, frames, [])


def read(path: str | Path, buses: set[str] | None = None, spec: Any = None) -> Trace:
    """Read trace.tsv, or (given the spec) a pcapng capture; anything malformed is a one-line UserError
    (`file:line: problem` for a trace)."""
    shown = str(path)
    if spec is not None:
        try:
            with open(path, "rb") as fh:
                magic = fh.read(4)
        except OSError as exc:
            raise UserError(located(shown, None, f"cannot read trace ({exc.strerror})")) from None
        if magic == PCAPNG_MAGIC:
            from captures.pcapng import read_file
            return from_capture(read_file(path), spec, shown)
    try:
        text = Path(path).read_text()
    except (OSError, UnicodeDecodeError) as exc:
        raise UserError(located(shown, None, f"cannot read trace ({getattr(exc, 'strerror', None) or exc})")) from None
    return parse_lines(text.splitlines(), shown, buses)


def parse_lines(lines: list[str], shown: str, buses: set[str] | None = None) -> Trace:
    """The rows of a trace (header first) as frames and notes; `shown` names the file in errors."""
    if not lines:
        raise UserError(located(shown, None, "empty trace (expected a header line)"))
    header = lines[0].split("\t")
    if tuple(header[:9]) != COLUMNS[:9]:
        raise UserError(located(shown, 1, f"not a bus trace: header must start with {' '.join(COLUMNS[:9])}"))
    has_sent = len(header) >= 10 and header[9] == "sent"
    frames: list[TraceFrame] = []
    notes: list[TraceNote] = []
    for no, raw in enumerate(lines[1:], start=2):
        if not raw.strip():
            continue
        cols = raw.split("\t")
        if len(cols) < 9:
            raise UserError(located(shown, no, f"expected {len(header)} tab-separated columns, got {len(cols)}"))
        try:
            start, end = float(cols[0]), float(cols[1])
        except ValueError:
            raise UserError(located(shown, no, f"start/end time is not a number: {cols[0]!r} {cols[1]!r}")) from None
        if not (0 <= start <= end):
            raise UserError(located(shown, no, f"frame ends before it starts ({start} > {end})"))
        bus = cols[2]
        if bus == DEBUG_BUS:
            event, *pairs = cols[6].split(" ")
            fields = {}
            for pair in pairs:
                k, sep, v = pair.partition("=")
                if not sep:
                    raise UserError(located(shown, no, f"debug row: expected key=value, got {pair!r}"))
                fields[k] = v
            notes.append(TraceNote(no, start, cols[3], event, fields))
            continue
        if buses is not None and bus not in buses:
            raise UserError(located(shown, no, f"unknown bus {bus!r} (spec buses: {', '.join(sorted(buses))})"))
        try:
            data = bytes.fromhex(cols[7])
            sent = bytes.fromhex(cols[9]) if has_sent and len(cols) > 9 and cols[9] else data
        except ValueError:
            raise UserError(located(shown, no, "bytes column is not hexadecimal")) from None
        flags = tuple(f for f in cols[8].split(",") if f)
        heard = None if "lost" in flags else data
        frames.append(TraceFrame(no, start, end, bus, cols[3], sent, heard, flags, _parse_or_none(sent), _intact(heard)))
    frames.sort(key=lambda f: (f.start, f.end, f.line))
    return Trace(shown, frames, notes)
