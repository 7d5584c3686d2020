"""Counterexamples as message sequence charts: Mermaid text and JSON.

Each step of a trace shows the arrows its rule declares (sender -> receiver:
message) plus the variables it changed, so a reader sees the protocol run, not
bit patterns. A liveness lasso wraps its cycle in a Mermaid `loop` block.
"""
from __future__ import annotations

import re
from typing import Any

from model_check.engine import Result, Violation


def _pid(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9_]", "_", name)


def steps_as_dicts(res: Result, v: Violation) -> list[dict[str, Any]]:
    lay, rules = res.compiled.layout, res.model.rules
    out = []
    prev: dict[str, int] | None = None
    for i, step in enumerate(v.trace):
        values = lay.unpack(step.state)
        changed = values if prev is None else {k: x for k, x in values.items() if prev[k] != x}
        entry: dict[str, Any] = {"step": i, "rule": None if step.rule is None else rules[step.rule].name,
                                 "changed": changed}
        if step.rule is not None:
            r = rules[step.rule]
            entry["ticks"] = r.ticks
            entry["events"] = [{"from": e.src, "to": e.dst, "message": e.text} for e in r.msc]
        out.append(entry)
        prev = values
    return out


def to_json(res: Result, v: Violation) -> dict[str, Any]:
    return {"model": res.model.name, "kind": v.kind, "property": v.prop, "detail": v.detail,
            "loop_start": v.loop_start, "tick_us": res.model.tick_us,
            "participants": res.model.participants, "steps": steps_as_dicts(res, v)}


def to_mermaid(res: Result, v: Violation) -> str:
    lines = ["sequenceDiagram"]
    parts = list(res.model.participants)
    for r in res.model.rules:
        for e in r.msc:
            for p in (e.src, e.dst):
                if p is not None and p not in parts:
                    parts.append(p)
    for p in parts:
        lines.append(f"    participant {_pid(p)} as {p}")
    anchor = _pid(parts[0]) if parts else "system"
    lines.append(f"    Note over {anchor}: {v.kind} violated: {v.prop}")
    time = 0
    for i, step in enumerate(steps_as_dicts(res, v)):
        if v.loop_start is not None and i == v.loop_start + 1 and i < len(v.trace):
            lines.append("    loop repeats forever")
        if step["rule"] is None:
            continue
        time += step.get("ticks", 0)
        events = step.get("events") or []
        for e in events:
            text = e["message"].replace(";", ",")
            if e["to"] is None:
                lines.append(f"    Note over {_pid(e['from'])}: {text}")
            else:
                lines.append(f"    {_pid(e['from'])}->>{_pid(e['to'])}: {text}")
        if not events:
            lines.append(f"    Note over {anchor}: {step['rule']} (t={time})")
    if v.loop_start is not None and v.loop_start + 1 < len(v.trace):
        lines.append("    end")
    if v.detail:
        lines.append(f"    Note over {anchor}: {v.detail}")
    return "\n".join(lines) + "\n"
