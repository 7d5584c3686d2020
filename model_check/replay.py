"""A counterexample as a runnable scenario: `arachnae check arbitration ... --replay DIR`.

The model's environment steps become timed injections in a sim2d scenario, so
the whole network runs the real node code under the counterexample's schedule:
`arrive_X` (a record becomes pending at slave X) is a `request: X` fault at the
step's time (tick x slot). The collisions are not injected: they must follow
from the nodes' own timing, which is the point of the replay. A counterexample
of the seed variant is written twice: as checked (`arbitration: {BUS: seed}`,
expected to starve a request for longer than K) and under the spec's rule with
the same schedule (expected to serve every request within K, without a
protocol violation).
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import yaml

from arachnae.errors import UserError
from arachnae.files import atomic_open, refuse_foreign
from model_check import msc
from model_check.engine import Result

# CHOICE: injections start after POST and the sensor set-up, which take about 2 s in the simulator
START_S = 3.0
# the run goes on this many slots after the last injection: the master's own polls take about half of
# them, and the rest must pass K of every contended bus (36 slots each) for a starvation to show
RUN_SLOTS = 160


def _schedule(res: Result) -> list[dict[str, Any]]:
    """The counterexample's arrivals and collisions with their time (ticks of the model before them);
    a collision inside the lasso's loop repeats forever (`forever`)."""
    v = res.violation
    out, ticks = [], 0
    names = [x.name for x in res.model.rules]
    for i, step in enumerate(msc.steps_as_dicts(res, v)):
        rule = step["rule"]
        if rule is None:
            continue
        r = res.model.rules[names.index(rule)]
        if r.actor is None:
            if not rule.startswith("arrive_"):
                raise UserError(f"--replay: no scenario injection for the environment step {rule!r}")
            out.append({"tick": ticks, "rule": rule, "node": rule.removeprefix("arrive_")})
        elif rule == "collision":
            forever = v.loop_start is not None and i > v.loop_start
            out.append({"tick": ticks, "rule": rule, "node": None, "forever": forever})
        ticks += step.get("ticks", 0)
    return out


def _faults(res: Result) -> list[dict[str, Any]]:
    """Arrivals as `request` faults; the collisions as one `collide` fault over the nodes that arrived
    (their transceivers miss each other's carrier for a slot, so same-slot requests collide as in the model)."""
    slot_s = res.model.tick_us * 1e-6
    sched = _schedule(res)
    faults: list[dict[str, Any]] = [{"at": round(START_S + e["tick"] * slot_s, 6), "request": e["node"]}
                                    for e in sched if e["rule"] != "collision"]
    hits = [e for e in sched if e["rule"] == "collision"]
    nodes = sorted({e["node"] for e in sched if e["node"]})
    if hits and len(nodes) >= 2:
        c: dict[str, Any] = {"at": round(START_S + hits[0]["tick"] * slot_s, 6), "collide": nodes}
        if not any(e["forever"] for e in hits):
            c["until"] = round(START_S + (hits[-1]["tick"] + 1) * slot_s, 6)
        faults.append(c)
    return faults


def scenario(res: Result, variant: str, command: str) -> dict[str, Any]:
    m, v = res.model, res.violation
    bus = m.origin["bus"]
    slot_s = m.tick_us * 1e-6
    faults = _faults(res)
    last = max((f["at"] for f in faults), default=START_S)
    arrivals = sum(1 for f in faults if "request" in f)
    expect: dict[str, Any] = {"post": "OPERATIONAL"}
    if variant == "seed":
        expect["metrics"] = {"protocol.starved": {"min": 1}}     # the lasso: a request waits past K
    else:
        expect["metrics"] = {"protocol.starved": {"eq": 0}, "protocol.served": {"min": arrivals}}
    return {
        "name": f"replay_{m.origin['model']}_{bus}_{variant}",
        "duration": round(last + RUN_SLOTS * slot_s, 3),
        "arena": {"size": [4.0, 3.0]},
        "robot": {"pose": [2.0, 1.5, 0], "task": "idle"},
        "arbitration": {bus: variant},
        "faults": faults,
        "expect": expect,
    }


REPLAY_MARK = "Replay written by arachnae check --replay"   # in each file it writes; such files may be replaced


def header(res: Result, variant: str, command: str) -> str:
    v = res.violation
    lines = [f"{REPLAY_MARK}: a counterexample of `{command}` ({res.model.name}):",
             f"{v.kind} {v.prop} violated" + (f" ({v.detail})." if v.detail else "."),
             f"Run with the {variant} arbitration rule on the real node code; the model's environment steps:"]
    for e in _schedule(res):
        what = f"{e['node']} requests the bus" if e["node"] else \
            "same-slot requests collide" + (" (in the loop: forever)" if e["forever"] else "")
        lines.append(f"  tick {e['tick']}: {e['rule']} -> {what}")
    return "".join(f"# {x}\n" for x in lines)


def write(res: Result, out_dir: str, command: str) -> list[Path]:
    """Write DIR/<model>_<bus>_<variant>.yaml (+ the spec variant for a seed counterexample) and the
    counterexample as JSON; returns the scenario files."""
    m = res.model
    if res.violation is None:
        raise UserError(f"--replay: {m.name} holds, there is no counterexample to replay")
    if m.origin.get("model") != "arbitration":
        raise UserError(f"--replay: only arbitration counterexamples replay in the simulator, not {m.name}")
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise UserError(f"--replay: {out_dir} is not a directory")
    variants = [m.origin["variant"]] + (["spec"] if m.origin["variant"] == "seed" else [])
    files: dict[Path, str] = {}
    for variant in variants:
        sc = scenario(res, variant, command)
        files[out / f"{sc['name']}.yaml"] = header(res, variant, command) + yaml.safe_dump(
            sc, sort_keys=False, default_flow_style=None)
    trace = dict(msc.to_json(res, res.violation), written_by=REPLAY_MARK)
    files[out / f"counterexample_{m.origin['bus']}.json"] = json.dumps(trace, indent=2) + "\n"
    for path in files:      # issue 10.1: a file of the user's by the same name is never replaced
        refuse_foreign(path, REPLAY_MARK, "--replay")
    out.mkdir(parents=True, exist_ok=True)
    for path, text in files.items():
        with atomic_open(path, "w") as fh:
            fh.write(text)
    return [p for p in files if p.suffix == ".yaml"]
