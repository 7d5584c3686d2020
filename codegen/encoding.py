"""Physical <-> raw value rules, defined once so that every codec rounds alike.

Both generated codecs work on integer milli-units (1/1000 of the field's unit), the
only representation an 8-bit firmware can compute exactly; Python's float helpers
are a convenience on top. Rounding is half away from zero. The logarithmic LSC
encoding (seed 3.2.16) is defined by threshold tables computed here, so C and
Python cannot disagree about a boundary.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from decimal import Decimal, getcontext
from fractions import Fraction

MILLI = 1000


def to_fraction(value: int | float | str) -> Fraction:
    """An exact rational from a YAML number or an 'a/b' string (floats read as written in decimal)."""
    if isinstance(value, str) and "/" in value:
        num, den = value.split("/")
        return Fraction(int(num), int(den))
    return Fraction(str(value))


def round_half_away(value: Fraction) -> int:
    """Round to the nearest integer, halves away from zero (the rule of both codecs)."""
    sign = -1 if value < 0 else 1
    return sign * math.floor(abs(value) + Fraction(1, 2))


@dataclass(frozen=True)
class Linear:
    """phys = raw * scale + offset."""

    scale: Fraction = Fraction(1)
    offset: Fraction = Fraction(0)

    @property
    def identity(self) -> bool:
        return self.scale == 1 and self.offset == 0

    def raw_exact(self, phys: Fraction) -> Fraction:
        return (phys - self.offset) / self.scale

    def to_raw(self, phys: Fraction) -> int:
        return round_half_away(self.raw_exact(phys))

    def to_phys(self, raw: int) -> Fraction:
        return raw * self.scale + self.offset

    def to_raw_milli(self, milli: int) -> int:
        return round_half_away(self.raw_exact(Fraction(milli, MILLI)))

    def to_phys_milli(self, raw: int) -> int:
        return round_half_away(self.to_phys(raw) * MILLI)


@dataclass(frozen=True)
class Log10:
    """raw = per_decade * log10(phys / ref), clamped to the field (seed 3.2.16: 1000 -> 255)."""

    ref: Fraction
    per_decade: int
    saturate: bool
    raw_max: int

    def _value(self, raw: Fraction | int) -> Decimal:
        getcontext().prec = 40  # far beyond any milli boundary of a 255-step table
        ref = Decimal(self.ref.numerator) / Decimal(self.ref.denominator)
        raw = Fraction(raw)
        exponent = Decimal(raw.numerator) / Decimal(raw.denominator) / Decimal(self.per_decade)
        return ref * (Decimal(10) ** exponent)

    def thresholds_milli(self) -> list[int]:
        """T[r-1] = smallest milli value that encodes to raw >= r, for r = 1..raw_max."""
        out = []
        for r in range(1, self.raw_max + 1):
            edge = self._value(Fraction(2 * r - 1, 2)) * MILLI
            out.append(int(edge.to_integral_value(rounding="ROUND_CEILING")))
        return out

    def phys_milli_table(self) -> list[int]:
        """Milli value of each raw code 0..raw_max, rounded half away from zero."""
        return [int((self._value(r) * MILLI).to_integral_value(rounding="ROUND_HALF_UP")) for r in range(self.raw_max + 1)]

    def to_raw_milli(self, milli: int) -> int:
        return sum(1 for t in self.thresholds_milli() if milli >= t)

    def to_phys_milli(self, raw: int) -> int:
        return self.phys_milli_table()[raw]

    def to_raw(self, phys: Fraction) -> int:
        """Unclamped code of a physical value (the lint compares it with the field's width)."""
        if phys <= 0:
            return -1
        exact = self.per_decade * (math.log10(phys) - math.log10(self.ref))
        return round_half_away(Fraction(exact).limit_denominator(10**9))

    def to_phys(self, raw: int) -> Fraction:
        return Fraction(str(self._value(raw)))


Encoding = Linear | Log10
