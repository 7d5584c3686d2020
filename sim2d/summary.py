"""A per-scenario table of the key metrics of a batch of runs (what a reviewer reads first).

Why a table of its own: metrics.json holds everything, but comparing twenty
scenarios x seeds needs one line each: did it pass, how far, how close to a
wall, how fast the reactions, which layer of the NP3 held control, how low
the battery voltage sagged and whether the PSC raised an alarm.
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Iterable

COLUMNS = ("scenario", "seed", "pass", "POST", "walked m", "collisions", "min clear m", "max react s",
           "control s (reflex/avoid/task)", "battery V min/mean/end", "PSC V low mean/level, alarms", "notes",
           "protocol violations; wait/K slots")
_NOTES = ("escape", "five_legged_gait", "operator_message", "blocked", "pit", "led_blink", "speech")


def _control(m: dict[str, Any]) -> str:
    c = (m.get("nodes", {}).get("NP3") or {}).get("control") or {}
    if not c:
        return "-"
    return "/".join(f"{c.get(k, 0.0):.0f}" for k in ("reflexes", "avoidance", "task"))


def _notes(m: dict[str, Any]) -> str:
    notes = m.get("notes", {})
    return " ".join(f"{k}={notes[k]['count']}" for k in _NOTES if k in notes) or "-"


def _volts(*values: Any) -> str:
    return "/".join("-" if v is None else f"{v:.2f}" for v in values)


def _battery(m: dict[str, Any]) -> tuple[str, str]:
    """seed 3.2.17 (issue 18): the battery's terminal voltage, and the PSC's view of it with its alarms."""
    b = m.get("battery")
    if not b:
        return "-", "-"
    psc = "-" if b.get("psc_alarms") is None else f"{_volts(b.get('psc_mean_min_v'), b.get('psc_level_min_v'))}, {b['psc_alarms']}"
    return _volts(b.get("v_min"), b.get("v_mean"), b.get("v_final")), psc


def _protocol(m: dict[str, Any]) -> str:
    """Issue 11: the run's trace against the verified protocol: violations, then each contended bus's longest
    wait against the checker's bound K."""
    p = m.get("protocol")
    if not p:
        return "-"
    waits = " ".join(f"{b} {w:.1f}/{p['k_slots'].get(b)}" for b, w in p.get("max_wait_slots", {}).items())
    return f"{p['violations']}; {waits}" if waits else str(p["violations"])


def row(m: dict[str, Any]) -> list[str]:
    exps = m.get("expectations", [])
    ok = all(e["passed"] for e in exps)
    r = m.get("max_reaction_s")
    clear = m.get("min_clearance_m")
    return [m["scenario"], str(m["seed"]), "PASS" if ok else "FAIL", str(m["post"]["verdict"]),
            f"{m['distance_walked_m']:.2f}", str(m["collisions"]), "-" if clear is None else f"{clear:.2f}",
            "-" if r is None else f"{r:.2f}", _control(m), *_battery(m), _notes(m), _protocol(m)]


def markdown(metrics: Iterable[dict[str, Any]]) -> str:
    rows = [row(m) for m in sorted(metrics, key=lambda m: (m["scenario"], m["seed"]))]
    lines = ["| " + " | ".join(COLUMNS) + " |", "|" + "---|" * len(COLUMNS)]
    lines += ["| " + " | ".join(r) + " |" for r in rows]
    return "\n".join(lines) + "\n"


def from_folder(root: str | Path) -> str:
    """The table over every <run>/metrics.json below `root` (the output of `arachnae sim batch`)."""
    found = sorted(Path(root).glob("*/metrics.json"))
    return markdown(json.loads(p.read_text()) for p in found)
