"""A capture as the logic levels of each bus: the UART waveform a logic analyser on the RS-485 receiver records.

Every byte goes out as one start bit (low), eight data bits least significant
first and `bits_per_char - 9` stop bits (high) at the bus's baud rate, from the
frame's start time (seed 3.2.1: RS-485; nodes.yaml: 8N1 framing, the baud rates).
The line idles high. Frames that overlap in time (a collision) drive the line
together: it is low while any of them drives it low, the wired-AND the
simulator models (sim2d.bus). The result is a VCD file, which sigrok-cli
(`-I vcd`), PulseView and GTKWave read; one wire per bus, named like the bus.
"""
from __future__ import annotations

from fractions import Fraction
from pathlib import Path
from typing import IO, Iterable

from arachnae.errors import UserError
from arachnae.files import atomic_open
from captures.pcapng import CapturedFrame

VCD_MARK = "ARACHNAE II bus lines (arachnae capture vcd)"   # the first line's comment: a VCD we may replace

DATA_BITS = 8
SAMPLES_PER_BIT = 16          # at least this many VCD time units per bit of the fastest bus written
TAIL_CHARS = 8                # idle line after the last frame, so a decoder sees its idle gap


def timescale_ns(bauds: Iterable[int]) -> int:
    """The coarsest power-of-ten time unit (in ns) that still gives SAMPLES_PER_BIT units per bit.

    >>> timescale_ns([2400]), timescale_ns([2400, 19200]), timescale_ns([1_000_000])
    (10000, 1000, 10)
    """
    bit_ns = min(Fraction(10**9, b) for b in bauds)
    unit = 1
    while unit * 10 * SAMPLES_PER_BIT <= bit_ns:
        unit *= 10
    return unit


def low_intervals(frames: Iterable[CapturedFrame], baud: int, bits_per_char: int, unit_ns: int) -> list[tuple[int, int]]:
    """[start, end) of every low stretch of one bus's line, in time units, merged and sorted."""
    stop_bits = bits_per_char - 1 - DATA_BITS
    if stop_bits < 1:
        raise UserError(f"bits_per_char {bits_per_char}: a UART character needs a start bit, {DATA_BITS} data bits and a stop bit")
    bit = Fraction(10**9, baud * unit_ns)               # one bit in time units, exact

    def at(t0: Fraction, k: int) -> int:
        return round(t0 + k * bit)

    raw = []
    for f in frames:
        t0 = Fraction(f.time_ns, unit_ns)
        for i, byte in enumerate(f.data):
            k0 = i * bits_per_char
            levels = [0] + [(byte >> j) & 1 for j in range(DATA_BITS)]    # start bit, data LSB first
            k = 0
            while k < len(levels):
                if levels[k]:
                    k += 1
                    continue
                run = k
                while run < len(levels) and not levels[run]:
                    run += 1
                raw.append((at(t0, k0 + k), at(t0, k0 + run)))
                k = run
    raw.sort()
    merged: list[tuple[int, int]] = []
    for a, b in raw:
        if merged and a <= merged[-1][1]:
            merged[-1] = (merged[-1][0], max(merged[-1][1], b))
        else:
            merged.append((a, b))
    return merged


def timescale_text(unit_ns: int) -> str:
    """A VCD $timescale: 1, 10 or 100 of s, ms, us or ns.

    >>> timescale_text(10), timescale_text(1000), timescale_text(10_000)
    ('10 ns', '1 us', '10 us')
    """
    for suffix, scale in (("s", 10**9), ("ms", 10**6), ("us", 10**3), ("ns", 1)):
        if unit_ns % scale == 0 and unit_ns // scale in (1, 10, 100):
            return f"{unit_ns // scale} {suffix}"
    raise ValueError(f"{unit_ns} ns is not a VCD time unit")


def write_vcd(stream: IO[str], lines: dict[str, list[tuple[int, int]]], unit_ns: int, end: int) -> None:
    """Value changes of every line (high when idle) up to time `end`."""
    ids = {name: chr(33 + n) for n, name in enumerate(lines)}
    stream.write(f"$comment {VCD_MARK} $end\n$timescale {timescale_text(unit_ns)} $end\n"
                 "$scope module arachnae $end\n")
    for name, ident in ids.items():
        stream.write(f"$var wire 1 {ident} {name} $end\n")
    stream.write("$upscope $end\n$enddefinitions $end\n")
    changes: dict[int, list[str]] = {}
    for name, intervals in lines.items():
        for a, b in intervals:
            changes.setdefault(a, []).append(f"0{ids[name]}")
            changes.setdefault(b, []).append(f"1{ids[name]}")
    initial = changes.pop(0, [])              # a line low from the very start
    stream.write("#0\n" + "".join(f"1{ident}\n" for ident in ids.values() if f"0{ident}" not in initial)
                 + "".join(f"{c}\n" for c in initial))
    for t in sorted(changes):
        stream.write(f"#{t}\n" + "".join(f"{c}\n" for c in changes[t]))
    stream.write(f"#{end}\n")


def capture_vcd(path: str | Path, frames: list[CapturedFrame], buses: dict) -> Path:
    """Write the lines of `buses` ({name: codegen.model.Bus}) as one VCD file, atomically; returns the path."""
    if not buses:
        raise UserError("capture vcd: no bus to write")
    unit = timescale_ns(b.baud for b in buses.values())
    lines = {name: low_intervals([f for f in frames if f.bus == name], b.baud, b.bits_per_char, unit)
             for name, b in buses.items()}
    last = max((f.time_ns + len(f.data) * buses[f.bus].bits_per_char * 10**9 // buses[f.bus].baud
                for f in frames if f.bus in buses), default=0)
    tail = max(TAIL_CHARS * b.bits_per_char * 10**9 // b.baud for b in buses.values())
    out = Path(path)
    with atomic_open(out, "w") as fh:
        write_vcd(fh, lines, unit, -(-(last + tail) // unit))
    return out
