"""Breadth-first explicit-state search: invariants, deadlocks, coverage, stats.

Breadth-first so that the first violation found has a shortest trace. Visited
states are packed ints in one set; the frontier of each depth is kept as a
list so a trace can be rebuilt afterwards by searching each layer for a
predecessor, which costs a pointer per state instead of a parent map.
"""
from __future__ import annotations

import sys
import time
from dataclasses import dataclass, field
from typing import TextIO

from model_check.compile import Compiled, compile_model
from model_check.gcl import Model


@dataclass
class Step:
    rule: int | None          # None for the initial state
    state: int                # concrete (not canonical) packed state


@dataclass
class Violation:
    kind: str                 # invariant | deadlock | final-check | liveness
    prop: str
    trace: list[Step]
    loop_start: int | None = None    # liveness: index in trace where the cycle begins
    detail: str = ""


@dataclass
class Result:
    model: Model
    compiled: Compiled
    states: int = 0
    transitions: int = 0
    depth: int = 0
    seconds: float = 0.0
    coverage: list[int] = field(default_factory=list)
    violation: Violation | None = None
    bounds: dict[str, int | None] = field(default_factory=dict)   # response -> worst ticks
    warnings: list[str] = field(default_factory=list)
    layers: list[list[int]] = field(default_factory=list)
    seen: set[int] = field(default_factory=set)

    @property
    def ok(self) -> bool:
        return self.violation is None

    @property
    def never_fired(self) -> list[str]:
        return [r.name for r, n in zip(self.model.rules, self.coverage) if n == 0]

    @property
    def rate(self) -> float:
        return self.states / self.seconds if self.seconds > 0 else float("inf")


class Progress:
    """A periodic line on stderr once a run has taken longer than `after` seconds."""

    def __init__(self, name: str, stream: TextIO | None = None, after: float = 3.0, every: float = 2.0):
        self.name, self.stream, self.after, self.every = name, stream or sys.stderr, after, every
        self.start = self.last = time.perf_counter()

    def update(self, depth: int, states: int, frontier: int) -> None:
        now = time.perf_counter()
        if now - self.start >= self.after and now - self.last >= self.every:
            self.last = now
            rate = states / (now - self.start)
            self.stream.write(f"[{self.name}] depth {depth}  states {states:,}  frontier {frontier:,}  "
                              f"{rate:,.0f} states/s  {now - self.start:.0f}s\n")
            self.stream.flush()


def explore(model: Model, compiled: Compiled | None = None, progress: bool = True,
            check_liveness: bool = True) -> Result:
    """Explore every reachable state; stop at the first safety violation."""
    comp = compiled or compile_model(model)
    res = Result(model=model, compiled=comp, coverage=[0] * len(model.rules))
    if model.symmetry and model.responses and check_liveness:
        res.warnings.append("symmetry reduction is sound for safety only: liveness results on the "
                            "reduced graph are not a proof")
    bar = Progress(model.name) if progress else None
    t0 = time.perf_counter()
    seen = {comp.init}
    frontier = [comp.init]
    layers = [frontier]
    hit = None
    expand, cov = comp.expand, res.coverage
    while frontier:
        frontier, hit = expand(frontier, seen, cov)
        if hit is not None:
            break
        if frontier:
            layers.append(frontier)
        if bar:
            bar.update(len(layers) - 1, len(seen), len(frontier))
    res.seconds = time.perf_counter() - t0
    res.states, res.transitions, res.depth = len(seen), sum(cov), len(layers) - 1
    res.layers, res.seen = layers, seen
    if hit is not None:
        kind, index, state = hit
        prop = model.invariants[index].name if kind == "invariant" else "no deadlock"
        res.violation = Violation(kind, prop, trace_to(res, state, len(layers) - 1))
        return res
    if model.final_checks:
        _final_checks(res)
        if res.violation:
            return res
    if check_liveness and model.responses:
        from model_check.liveness import check_responses
        check_responses(res)
    return res


def _final_checks(res: Result) -> None:
    """Python-only checks (e.g. an oracle) on every state satisfying the model's `final`."""
    comp, model = res.compiled, res.model
    final = comp.predicates["final"]
    for depth, layer in enumerate(res.layers):
        for s in layer:
            if not final(s):
                continue
            values = comp.layout.unpack(s)
            for name, check in model.final_checks:
                problem = check(values)
                if problem:
                    res.violation = Violation("final-check", name, trace_to(res, s, depth), detail=problem)
                    return


def depth_of(res: Result, state: int) -> int:
    for d, layer in enumerate(res.layers):
        if state in set(layer):
            return d
    raise KeyError(state)


def trace_to(res: Result, target: int, depth: int | None = None) -> list[Step]:
    """A shortest trace from the initial state to the canonical `target`, as concrete states."""
    comp = res.compiled
    if depth is None:
        depth = depth_of(res, target)
    chain = [target]
    for d in range(depth - 1, -1, -1):
        want = chain[-1]
        for s in res.layers[d]:
            if any(comp.canon(ns) == want for _, ns in comp.successors(s)):
                chain.append(s)
                break
        else:  # pragma: no cover - would mean the search lost a state
            raise RuntimeError("trace reconstruction failed")
    chain.reverse()
    return concretise(comp, chain)


def concretise(comp: Compiled, canonical_chain: list[int]) -> list[Step]:
    """Replay a chain of canonical states as a real run (symmetry may permute nodes)."""
    return [Step(None, comp.init_raw)] + follow(comp, comp.init_raw, canonical_chain[1:])


def follow(comp: Compiled, start: int, path: list[int]) -> list[Step]:
    """Steps from a concrete state along canonical states `path` (excluding start)."""
    steps, cur = [], start
    for want in path:
        for rule, ns in comp.successors(cur):
            if comp.canon(ns) == want:
                steps.append(Step(rule, ns))
                cur = ns
                break
        else:  # pragma: no cover
            raise RuntimeError("trace concretisation failed")
    return steps


