"""Physical value <-> raw wire value through the generated field conversions, saturating.

The generated `FieldInfo.conv` is exact (fractions) and raises on values out
of range, as a codec must. A sensor's ADC or a servo command instead
saturates at the field's limits, and runs thousands of times per simulated
minute, so this wraps the same conversion (scale, offset, log table of the
spec) in a float function that clamps to the field's raw range.
"""
from __future__ import annotations

import bisect
import math
from typing import Callable

from arachnae_proto.convert import LinearConv, LogConv
from arachnae_proto.messages import Message


class Quantizer:
    """raw(phys) saturating at the field's range; phys(raw) in the field's unit."""

    __slots__ = ("raw", "phys", "lo", "hi")

    def __init__(self, raw: Callable[[float], int], phys: Callable[[int], float], lo: int, hi: int) -> None:
        self.raw, self.phys, self.lo, self.hi = raw, phys, lo, hi


def quantizer(message: type[Message], field: str) -> Quantizer:
    """The saturating conversion of `message.field` (seed encodings, SPEC-NOTES decision 7)."""
    info = next(f for f in message.FIELDS if f.name == field)
    conv = info.conv
    if isinstance(conv, LinearConv):
        scale, offset, lo, hi = float(conv.scale), float(conv.offset), conv.lo, conv.hi

        def raw(phys: float) -> int:
            x = (phys - offset) / scale
            r = int(math.floor(abs(x) + 0.5))            # half away from zero, like the generated codec
            r = r if x >= 0 else -r
            return lo if r < lo else hi if r > hi else r

        def phys(r: int) -> float:
            return r * scale + offset

        return Quantizer(raw, phys, lo, hi)
    if isinstance(conv, LogConv):
        edges, lo, hi = conv.thresholds, conv.lo, conv.hi

        def raw_log(phys: float) -> int:
            r = bisect.bisect_right(edges, int(math.floor(phys * 1000 + 0.5))) if phys > 0 else lo
            return lo if r < lo else hi if r > hi else r

        return Quantizer(raw_log, conv.to_phys, lo, hi)
    raise ValueError(f"{message.NAME}.{field} has no physical conversion")
