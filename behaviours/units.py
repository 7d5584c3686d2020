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

from arachnae_proto import messages as _M
from arachnae_proto.convert import LinearConv, LogConv
from arachnae_proto.messages import Message

# seed 3.2.11: each sensor role's own XMIT_DATA layout, the record it answers the SPU's XMIT_DATA with
# (spec: the sensor bus's fetch_message and the records marked `record: true`)
XMIT_DATA_OF: dict[str, type[Message]] = {role: records[0] for role, records in _M.FETCHED_RECORDS[_M.XmitData].items()}


def record_byte(raw: int) -> int:
    """A raw field value as a record's value byte (spec XMIT_RECORD: signed fields as two's complement)."""
    return raw & 0xFF


def from_record_byte(value: int, signed: bool) -> int:
    """The raw field value a record's value byte carries (inverse of record_byte)."""
    return value - 256 if signed and value > 127 else value


class Quantizer:
    """raw(phys) saturating at the field's range; phys(raw) in the field's unit."""

    __slots__ = ("raw", "phys", "lo", "hi")

    def __init__(self, raw: Callable[[float], int], phys: Callable[[int], float], lo: int, hi: int) -> None:
        self.raw, self.phys, self.lo, self.hi = raw, phys, lo, hi


def quantizer(message: type[Message], field: str) -> Quantizer:
    """The saturating conversion of `message.field` (seed encodings, docs/decisions.md D7)."""
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


# spec XMIT_RECORD / DATA `age` (issue 17): how long ago the source measured the value, saturating
RECORD_AGE = quantizer(_M.XmitRecord, "age")


def age_byte(seconds: float) -> int:
    """A record's age field for a value measured `seconds` ago (older than the field reaches: its top)."""
    return RECORD_AGE.raw(max(0.0, seconds))


def values_quantizer(values: _M.RecordValues) -> Quantizer:
    """The conversion of a sensor's record values (spec record_values: one encoding for all its fields)."""
    return quantizer(values.message, values.fields[0])


# seed 3.2.2, 6.2: per sensor role whose records carry a number (the TPSC's carry contact flags), the conversion of
# the value byte (a record's value is the raw value of one of its record_values, signed as two's complement)
RECORD_QUANTIZER: dict[str, Quantizer] = {
    role: values_quantizer(r) for role, r in _M.RECORD_VALUES.items()
    if next(f for f in r.message.FIELDS if f.name == r.fields[0]).conv is not None}
