"""Breadth-first explicit-state search: invariants, deadlocks, coverage, stats.

Breadth-first so that the first violation found has a shortest trace. The
generated `edges` function expands one layer into a list of successors; the
StateStore (model_check.storage) deduplicates them in bulk and keeps the whole
graph in numpy arrays -- ids in first-seen order, BFS parents, edges -- so
traces walk up the parents and the response checks (model_check.liveness) run
on the stored graph without expanding any state again.
"""
from __future__ import annotations

import sys
import time
from dataclasses import dataclass, field
from typing import TextIO

from model_check.compile import Compiled, compile_model
from model_check.gcl import Model
from model_check.liveness import check_responses
from model_check.storage import Meter, StateStore
from model_check.trace import Step, Violation, concretise, follow

SLICE = 1 << 15          # frontier states expanded per call of the generated `edges`

__all__ = ["Result", "Step", "Violation", "explore", "trace_to", "concretise", "follow", "depth_of"]


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
    store: StateStore | None = None           # the explored graph (None once released)
    layer_starts: list[int] = field(default_factory=list)   # first id of each breadth-first layer
    times: dict[str, float] = field(default_factory=dict)    # search / bounds / liveness CPU seconds
    peak_bytes: int = 0                        # resident memory the check added at its peak
    store_bytes: int = 0                       # bytes of the stored graph (states, parents, edges)
    cpu: float = 0.0                           # CPU seconds of the whole check (search and properties)
    proof: bool = True                         # False after a bitstate search: a pass proves nothing

    @property
    def ok(self) -> bool:
        return self.violation is None

    @property
    def never_fired(self) -> list[str]:
        return [r.name for r, n in zip(self.model.rules, self.coverage) if n == 0]

    @property
    def rate(self) -> float:
        """States per CPU second of the search (wall seconds mislead on a shared machine)."""
        cpu = self.times.get("search", self.seconds)
        return self.states / cpu if cpu > 0 else float("inf")

    @property
    def bytes_per_state(self) -> float:
        """Resident peak per state: the figure that matters on big models (fixed overheads
        dominate it on tiny ones, where `store_bytes_per_state` is the per-state cost)."""
        return self.peak_bytes / max(self.states, 1)

    @property
    def store_bytes_per_state(self) -> float:
        return self.store_bytes / max(self.states, 1)

    @property
    def layers(self) -> list[list[int]]:
        """The states of each breadth-first layer (decoded from the store: for tests and tools)."""
        st = self._graph()
        return [st.states(range(a, b)) for a, b in zip(self.layer_starts, self.layer_starts[1:])]

    @property
    def seen(self) -> set[int]:
        st = self._graph()
        return set(st.states(range(len(st))))

    def _graph(self) -> StateStore:
        if self.store is None:
            raise RuntimeError("the state graph of this result was released")
        return self.store

    def release(self) -> None:
        """Drop the stored graph (the verdict, bounds and counterexample stay)."""
        self.store = None


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
    meter = Meter()
    bar = Progress(model.name) if progress else None
    t0, c0 = time.perf_counter(), time.process_time()
    store = StateStore(comp.layout.total_bits, len(model.rules))
    store.add_initial(comp.init)
    frontier, lo = [comp.init], 0
    res.layer_starts = [0, 1]
    hit = None
    edges = comp.edges
    while frontier:
        # a wide layer goes in slices: the successor lists and their dedup dicts are the search's
        # biggest Python objects; slicing changes nothing (the table dedups across slices, and ids,
        # parents and the next frontier come out in the same first-seen order)
        new = []
        for a in range(0, len(frontier), SLICE):
            nxt: list[int] = []
            rules: list[int] = []
            ends: list[int] = []
            hit = edges(frontier[a:a + SLICE], nxt, rules, ends)
            new += store.add_layer(lo + a, nxt, rules, ends)
            if hit is not None:
                hit_id = lo + a + len(ends)
                break
        if hit is not None:
            break
        lo += len(frontier)
        frontier = new
        if frontier:
            res.layer_starts.append(lo + len(frontier))
        if bar:
            bar.update(len(res.layer_starts) - 2, len(store), len(frontier))
    res.store_bytes = store.nbytes         # before finish drops the hash table: the search's peak
    store.finish()
    res.store = store
    res.seconds = time.perf_counter() - t0
    res.times["search"] = time.process_time() - c0     # CPU seconds: comparable on a busy machine
    res.coverage = store.coverage()
    res.states, res.transitions, res.depth = len(store), sum(res.coverage), len(res.layer_starts) - 2
    try:
        if hit is not None:
            kind, index, state = hit
            prop = model.invariants[index].name if kind == "invariant" else "no deadlock"
            res.violation = Violation(kind, prop, concretise(comp, store.states(store.path_to(hit_id))))
            return res
        if model.final_checks:
            c1 = time.process_time()
            _final_checks(res)
            res.times["final checks"] = time.process_time() - c1
            if res.violation:
                return res
        if check_liveness and model.responses:
            check_responses(res)
        return res
    finally:
        res.peak_bytes = meter.peak()
        res.cpu = time.process_time() - c0


def _final_checks(res: Result) -> None:
    """Python-only checks (e.g. an oracle) on every state satisfying the model's `final`."""
    comp, model, store = res.compiled, res.model, res._graph()
    final = store.mask(comp.layout, model.defs, model.final)
    final[res.layer_starts[-1]:] = False
    for i in final.nonzero()[0].tolist():
        values = comp.layout.unpack(store.state(i))
        for name, check in model.final_checks:
            problem = check(values)
            if problem:
                res.violation = Violation("final-check", name,
                                          concretise(comp, store.states(store.path_to(i))), detail=problem)
                return


def depth_of(res: Result, state: int) -> int:
    i = res._graph().index_of(state)
    return max(d for d, start in enumerate(res.layer_starts) if start <= i)


def trace_to(res: Result, target: int, depth: int | None = None) -> list[Step]:
    """A shortest trace from the initial state to the canonical `target`, as concrete states.

    The breadth-first parent of a state is the first state of the layer before that has an
    edge to it, so this is the same trace a search of the layers for predecessors gives."""
    store = res._graph()
    return concretise(res.compiled, store.states(store.path_to(store.index_of(target))))
