"""pcapng captures of the buses: one interface per bus, every frame with its bytes, time and marks.

Format: the pcapng block format (IETF draft-ietf-opsawg-pcapng): a Section Header
Block, one Interface Description Block per bus (if_name = bus name, link type =
the spec's user DLT `frame.pcap_linktype`, if_tsresol = nanoseconds, if_speed = baud)
and one Enhanced Packet Block per frame: the bytes on the line, the time its
start bit began, epb_flags with the link-layer errors a tap can see in the bytes
(bit 24 CRC error, 25 too long, 26 too short) and one opt_comment per mark the
simulator knows (`flag: collision`, `flag: corrupt`, `flag: lost`, `flag: delayed`,
`sender: NODE`, `sent: HEX` when the line carried other bytes than were sent).

Writing packs the blocks with `struct` (python-pcapng's block objects cost about
60 us a frame, a quarter of a simulation run's time); reading uses python-pcapng,
which also copes with what other tools write (either byte order, blocks we never
write, several sections).
"""
from __future__ import annotations

import functools

import struct
from pathlib import Path
from typing import IO, Iterable, NamedTuple

from arachnae.errors import UserError, located
from arachnae.files import atomic_open

# Block types and option codes (pcapng sections 4.1-4.3, 3.5).
_SHB, _IDB, _EPB = 0x0A0D0D0A, 0x00000001, 0x00000006
_BYTE_ORDER_MAGIC = 0x1A2B3C4D
_OPT_END, _OPT_COMMENT = 0, 1
_SHB_USERAPPL = 4
_IF_NAME, _IF_DESCRIPTION, _IF_SPEED, _IF_TSRESOL = 2, 3, 8, 9
_EPB_FLAGS = 2
TSRESOL_NS = 9                      # if_tsresol: 10^-9 s per timestamp unit
# epb_flags link-layer-dependent errors (pcapng 4.3.1)
FLAG_CRC_ERROR, FLAG_TOO_LONG, FLAG_TOO_SHORT = 1 << 24, 1 << 25, 1 << 26

COMMENT_FLAG, COMMENT_SENDER, COMMENT_SENT = "flag: ", "sender: ", "sent: "


class Interface(NamedTuple):
    """One capture interface: a bus (or any other line carrying frames of the spec)."""

    name: str
    linktype: int
    description: str = ""
    speed_bps: int = 0              # if_speed: the line's baud rate, 0 when unknown


class CapturedFrame(NamedTuple):
    """One frame on one line, as a tap on the line saw it."""

    bus: str                        # interface name
    time_ns: int                    # when its first start bit began, on the line's clock
    data: bytes                     # the bytes on the line
    flags: tuple[str, ...] = ()     # marks, e.g. sim2d.bus's collision, corrupt, lost, delayed
    sender: str = ""                # the node that drove the line, when known
    sent: bytes | None = None       # what the sender meant, when the line carried other bytes


class Capture(NamedTuple):
    interfaces: tuple[Interface, ...]
    frames: list[CapturedFrame]


def bus_interfaces(spec) -> tuple[Interface, ...]:
    """One interface per bus of the spec, in the spec's order."""
    return tuple(Interface(b.name, spec.frame.pcap_linktype, b.long, b.baud) for b in spec.buses.values())


@functools.lru_cache(maxsize=1 << 16)     # a run's capture repeats most of its frames (polls, set-points)
def link_errors(data: bytes) -> int:
    """The epb_flags error bits a receiver finds in the bytes themselves (size and CRC, like the codec)."""
    from arachnae_proto import CodecError, ErrorKind
    from arachnae_proto.frame import check

    try:
        check(data)
    except CodecError as err:
        return {ErrorKind.CHECKSUM: FLAG_CRC_ERROR, ErrorKind.OVERSIZE: FLAG_TOO_LONG,
                ErrorKind.TRUNCATED: FLAG_TOO_SHORT}.get(err.kind, 0)
    return 0


# -- writing ----------------------------------------------------------------------------
def _option(code: int, value: bytes) -> bytes:
    return struct.pack("<HH", code, len(value)) + value + b"\0" * (-len(value) % 4)


def _options(items: list[tuple[int, bytes]]) -> bytes:
    if not items:
        return b""
    return b"".join(_option(c, v) for c, v in items) + struct.pack("<HH", _OPT_END, 0)


def _block(block_type: int, body: bytes) -> bytes:
    total = 12 + len(body)
    return struct.pack("<II", block_type, total) + body + struct.pack("<I", total)


class PcapngWriter:
    """Streams a capture: the header and interfaces at once, then one block per frame (a live monitor
    flushes after each)."""

    def __init__(self, stream: IO[bytes], interfaces: Iterable[Interface], application: str = "arachnae") -> None:
        self.stream = stream
        self.interfaces = tuple(interfaces)
        self._index = {i.name: n for n, i in enumerate(self.interfaces)}
        if len(self._index) != len(self.interfaces):
            raise ValueError("two capture interfaces with the same name")
        shb = struct.pack("<IHHq", _BYTE_ORDER_MAGIC, 1, 0, -1) + _options([(_SHB_USERAPPL, application.encode())])
        out = [_block(_SHB, shb)]
        for i in self.interfaces:
            opts = [(_IF_NAME, i.name.encode()), (_IF_TSRESOL, bytes([TSRESOL_NS]))]
            if i.description:
                opts.append((_IF_DESCRIPTION, i.description.encode()))
            if i.speed_bps:
                opts.append((_IF_SPEED, struct.pack("<Q", i.speed_bps)))
            out.append(_block(_IDB, struct.pack("<HHI", i.linktype, 0, 0) + _options(opts)))
        stream.write(b"".join(out))

    def write(self, f: CapturedFrame) -> None:
        try:
            iface = self._index[f.bus]
        except KeyError:
            raise ValueError(f"frame on {f.bus!r}, which is not an interface of this capture") from None
        if f.time_ns < 0:
            raise ValueError(f"frame at {f.time_ns} ns: pcapng times are not negative")
        opts = [(_OPT_COMMENT, (COMMENT_FLAG + flag).encode()) for flag in f.flags]
        if f.sender:
            opts.append((_OPT_COMMENT, (COMMENT_SENDER + f.sender).encode()))
        if f.sent is not None and f.sent != f.data:
            opts.append((_OPT_COMMENT, (COMMENT_SENT + f.sent.hex()).encode()))
        errors = link_errors(f.data)
        if errors:
            opts.append((_EPB_FLAGS, struct.pack("<I", errors)))
        n = len(f.data)
        body = (struct.pack("<IIIII", iface, f.time_ns >> 32, f.time_ns & 0xFFFFFFFF, n, n)
                + f.data + b"\0" * (-n % 4) + _options(opts))
        self.stream.write(_block(_EPB, body))


def write_file(path: str | Path, interfaces: Iterable[Interface], frames: Iterable[CapturedFrame]) -> Path:
    """Write a whole capture; the file appears only when complete (temp file, then rename)."""
    out = Path(path)
    with atomic_open(out, "wb") as fh:
        writer = PcapngWriter(fh, interfaces)
        for f in frames:
            writer.write(f)
    return out


# -- reading ----------------------------------------------------------------------------
def _ticks_to_ns(ticks: int, tsresol: bytes | None) -> int:
    """Exact nanoseconds from a timestamp in the interface's resolution (default microseconds)."""
    code = tsresol[0] if tsresol else 6
    exp = code & 0x7F
    if code & 0x80:                                  # negative power of two
        return (ticks * 10**9 + (1 << (exp - 1) if exp else 0)) >> exp
    return ticks * 10 ** (9 - exp) if exp <= 9 else (ticks + 10 ** (exp - 9) // 2) // 10 ** (exp - 9)


def _opt(options, name: str, default):
    return options[name] if name in options else default


def _frame_from(block, names: dict[int, str], section) -> CapturedFrame:
    iface = section.interfaces[block.interface_id]
    ticks = (block.timestamp_high << 32) | block.timestamp_low
    time_ns = _ticks_to_ns(ticks, _opt(iface.options, "if_tsresol", None)) + _opt(iface.options, "if_tsoffset", 0) * 10**9
    flags, sender, sent = [], "", None
    for c in (block.options.get_all("opt_comment") if "opt_comment" in block.options else []):
        if c.startswith(COMMENT_FLAG):
            flags.append(c[len(COMMENT_FLAG):])
        elif c.startswith(COMMENT_SENDER):
            sender = c[len(COMMENT_SENDER):]
        elif c.startswith(COMMENT_SENT):
            try:
                sent = bytes.fromhex(c[len(COMMENT_SENT):])
            except ValueError:
                pass                                 # someone else's comment: not ours to read
    return CapturedFrame(names[block.interface_id], time_ns, bytes(block.packet_data), tuple(flags), sender, sent)


def read_file(path: str | Path) -> Capture:
    """Every interface and frame of a pcapng file; a file that is not one is a one-line UserError."""
    import pcapng
    from pcapng import blocks
    from pcapng.exceptions import PcapngException

    interfaces: list[Interface] = []
    frames: list[CapturedFrame] = []
    names: dict[int, str] = {}
    section = None
    try:
        with open(path, "rb") as fh:
            for block in pcapng.FileScanner(fh):
                if isinstance(block, blocks.SectionHeader):
                    section, names = block, {}
                elif isinstance(block, blocks.InterfaceDescription):
                    name = _opt(block.options, "if_name", f"if{len(interfaces)}")
                    names[block.interface_id] = name
                    interfaces.append(Interface(name, block.link_type, _opt(block.options, "if_description", ""),
                                                _opt(block.options, "if_speed", 0)))
                elif isinstance(block, blocks.EnhancedPacket):
                    frames.append(_frame_from(block, names, section))
    except OSError as exc:
        raise UserError(located(str(path), None, f"cannot read the capture ({exc.strerror or exc})")) from None
    except (PcapngException, ValueError, KeyError, IndexError, struct.error) as exc:
        raise UserError(located(str(path), None, f"not a readable pcapng capture ({type(exc).__name__}: {exc})")) from None
    if section is None:
        raise UserError(located(str(path), None, "not a pcapng capture (no section header block)"))
    return Capture(tuple(interfaces), frames)
