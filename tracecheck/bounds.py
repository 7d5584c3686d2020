"""The response bound K of each contended bus, as `arachnae check arbitration` proves it.

Exploring the arbitration model takes seconds, so the bounds are cached per
spec hash and per source of the model and its adapter (a change to either
recomputes them): a simulation run never pays for the proof twice.
"""
from __future__ import annotations

import hashlib
import json
import os
import tempfile
from dataclasses import asdict, dataclass
from pathlib import Path

from model_check import liveness, spec_adapter
from model_check.engine import explore
from model_check.models import arbitration

VARIANT = "spec"         # the bound the trace is held to is the spec variant's


@dataclass(frozen=True)
class BusBound:
    bus: str
    slot_us: float
    k_ticks: int | None                  # None: the model proves no bound (e.g. scope colliders)
    served_ticks: dict[str, int | None]  # per slave


def _fingerprint(spec) -> str:
    h = hashlib.sha256(spec.hash.encode())
    for mod in (arbitration, spec_adapter, liveness):
        h.update(Path(mod.__file__).read_bytes())
    return h.hexdigest()


def _cache_file() -> Path:
    root = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(root) / "arachnae" / "k_bounds.json"


def prove(spec, bus: str) -> BusBound:
    """Run the checker on the bus's arbitration model (spec variant, every requesting slave)."""
    p = spec_adapter.arbitration(spec, bus)
    res = explore(arbitration.build(p, VARIANT), progress=False)
    served = {k.removeprefix("served_"): v for k, v in res.bounds.items()}
    finite = [v for v in served.values() if isinstance(v, int)]
    k = max(finite) if res.ok and finite and len(finite) == len(served) else None
    return BusBound(bus, p.slot_us, k, served)


_MEMO: dict[str, dict[str, BusBound]] = {}


def _bounds(spec) -> dict[str, BusBound]:
    key = _fingerprint(spec)
    if key in _MEMO:
        return _MEMO[key]
    path = _cache_file()
    try:
        cached = json.loads(path.read_text())
        if cached.get("key") == key:
            _MEMO[key] = {b: BusBound(**v) for b, v in cached["buses"].items()}
            return _MEMO[key]
    except (OSError, ValueError, KeyError, TypeError):
        pass
    out = {b: prove(spec, b) for b, x in spec.buses.items() if x.arbitration != "polled"}
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=".k_bounds.")
        with os.fdopen(fd, "w") as fh:
            json.dump({"key": key, "buses": {b: asdict(v) for b, v in out.items()}}, fh)
        os.replace(tmp, path)
    except OSError:
        pass                    # a read-only home: prove again next time
    _MEMO[key] = out
    return out


def bounds(spec) -> dict[str, BusBound]:
    """K per contended bus (cached by spec hash and model source)."""
    return _bounds(spec)
