"""The POST verdict from the spec's declared rules (seed 6.3, SPEC-NOTES decision 3)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True)
class Verdict:
    verdict: str
    missing: tuple[str, ...]
    reasons: tuple[str, ...]


def verdict(spec: Any, missing_addresses: list[int]) -> Verdict:
    """HALTED when a required node outside every quorum or a quorum's minimum is lost,
    DEGRADED when an optional node or a quorum member is lost, else OPERATIONAL."""
    missing = {spec.node_at(a).short for a in missing_addresses if spec.node_at(a) is not None}
    halted, degraded = [], []
    in_quorum: set[str] = set()
    for q in spec.post.quorums:
        units: dict[Any, list[Any]] = {}
        for n in spec.nodes:
            if n.role in q.unit_roles:
                units.setdefault(getattr(n, q.unit_key), []).append(n)
                in_quorum.add(n.short)
        complete = [k for k, ns in units.items() if not any(n.short in missing for n in ns)]
        if len(complete) < q.min_complete:
            halted.append(f"{q.name}: {len(complete)} of {len(units)} complete, at least {q.min_complete} needed")
        elif len(complete) < len(units):
            lost = sorted(set(units) - set(complete))
            degraded.append(f"{q.name}: {', '.join(str(k) for k in lost)} incomplete")
    for n in spec.nodes:
        if n.short in missing and n.short not in in_quorum:
            (halted if n.required else degraded).append(f"{n.short} missing ({n.status})")
    if halted:
        return Verdict("HALTED", tuple(sorted(missing)), tuple(halted))
    if degraded:
        return Verdict("DEGRADED", tuple(sorted(missing)), tuple(degraded))
    return Verdict("OPERATIONAL", (), ())
