"""Physical value -> raw wire value, exactly as the spec encodes each sensor field.

The ONE place sim2d converts units to wire values. Each conversion is the
spec field's own encoding (codegen.model / codegen.encoding), so a change of
scale or range in spec/messages.yaml reaches the simulated sensors unchanged;
out-of-range values saturate at the field's raw limits, as a sensor's ADC does.
"""
from __future__ import annotations

from functools import lru_cache
from typing import Any


_SPEC: list[Any] = []


def use_spec(s: Any) -> None:
    """Use an already loaded spec (the simulation's) instead of loading one."""
    if not _SPEC or _SPEC[0] is not s:
        _SPEC[:] = [s]
        _field.cache_clear()
        _converter.cache_clear()


def spec() -> Any:
    if not _SPEC:
        from codegen.model import load_spec
        _SPEC.append(load_spec())
    return _SPEC[0]


@lru_cache(maxsize=None)
def _field(message: str, name: str) -> Any:
    return spec().message(message).field(name)


@lru_cache(maxsize=None)
def _converter(message: str, name: str) -> Any:
    """A fast phys -> raw function for one field, equal to the spec's rule (half away from zero)."""
    import bisect
    import math

    f = _field(message, name)
    lo, hi = f.raw_range
    lim_lo, lim_hi = f.raw_limits
    lo, hi = max(lo, lim_lo), min(hi, lim_hi)
    enc = f.encoding
    if enc.__class__.__name__ == "Log10":
        edges = enc.thresholds_milli()            # exact table from codegen.encoding

        def conv(phys: float) -> int:
            raw = bisect.bisect_right(edges, math.floor(phys * 1000)) if phys > 0 else lo
            return lo if raw < lo else hi if raw > hi else raw
    else:
        scale, offset = float(enc.scale), float(enc.offset)

        def conv(phys: float) -> int:
            x = (phys - offset) / scale
            raw = int(math.floor(abs(x) + 0.5)) * (1 if x >= 0 else -1)
            return lo if raw < lo else hi if raw > hi else raw
    return conv


def to_raw(message: str, name: str, phys: float) -> int:
    """Raw value of `phys` in the field's encoding, saturated at the field's limits."""
    return _converter(message, name)(phys)


def to_phys(message: str, name: str, raw: int) -> float:
    return float(_field(message, name).encoding.to_phys(raw))


def usrc_distance(metres: float) -> int:
    """seed 3.2.11: 0..255 = 0..10 m."""
    return to_raw("XMIT_DATA_USRC", "distance", metres)


def irrc_distance(metres: float) -> int:
    """seed 3.2.13: 0..255 = 0..10 cm (the spec field is in cm)."""
    return to_raw("XMIT_DATA_IRRC", "center", metres * 100.0)


def irrc_metres(raw: int) -> float:
    return to_phys("XMIT_DATA_IRRC", "center", raw) / 100.0


def usrc_metres(raw: int) -> float:
    return to_phys("XMIT_DATA_USRC", "distance", raw)


def tsc_temperature(celsius: float) -> int:
    """seed 3.2.15: int8 two's complement degrees C, -20..100."""
    return to_raw("XMIT_DATA_TSC", "temperature", celsius)


def lsc_light(lux: float) -> int:
    """seed 3.2.16: logarithmic, 0.1 -> 0, 1 -> 64, 10 -> 128, 100 -> 192, 1000 -> 255."""
    return to_raw("XMIT_DATA_LSC", "brightness", lux)


def isc_inclination(degrees: float, step: float = 3.0) -> int:
    """seed 3.2.14: -60..+60 degrees; the sensor itself resolves only `step` degrees (+-3)."""
    return to_raw("XMIT_DATA_ISC", "longitudinal", step * round(degrees / step))


def psc_voltage(volts: float) -> int:
    """seed 3.2.17: 4.2..5.0 V in the spec's resolution."""
    return to_raw("XMIT_DATA_PSC", "voltage", volts)


def tpsc_whiskers(left: bool, right: bool) -> int:
    """seed 3.2.12: OBJ_LEFT, OBJ_RIGHT or OBJ_BOTH bit; 0 for no contact."""
    bits = spec().flags["TPSC_CONTACT"].bits
    if left and right:
        return bits["OBJ_BOTH"]
    if left:
        return bits["OBJ_LEFT"]
    if right:
        return bits["OBJ_RIGHT"]
    return 0
