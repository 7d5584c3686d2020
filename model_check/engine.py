"""Breadth-first explicit-state search: invariants, deadlocks, coverage, stats.

Breadth-first so that the first violation found has a shortest trace. The
generated `edges` function expands one layer into a list of successors; the
StateStore (model_check.storage) deduplicates them in bulk and keeps the whole
graph in numpy arrays -- ids in first-seen order, BFS parents, edges -- so
traces walk up the parents and the response checks (model_check.liveness) run
on the stored graph without expanding any state again.
"""
from __future__ import annotations

import os
import sys
import time
from dataclasses import dataclass, field
from typing import TextIO

import numpy as np

from model_check import parallel
from model_check.compile import Compiled, RangeError, compile_model
from model_check.gcl import Model
from model_check.liveness import check_responses
from model_check.native import HIT_RANGE, Native
from model_check.storage import Meter, StateStore
from model_check.trace import Step, Violation, concretise, follow

SLICE = 1 << 15          # frontier states expanded per call of the generated `edges`
NATIVE_AFTER = 1 << 13   # states searched in Python before the compiled successor function takes over

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
    native: Native | None = None               # the compiled model the search ended on (None: Python)
    rounds: parallel.Rounds | None = None      # what the threads did (--workers > 1)

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
        """The summary line's bytes/state: the resident memory the check added at its peak
        (storage.Meter: VmHWM, reset at the check's start, minus VmRSS then, minus the code pages
        it faulted in: the interpreter, the imports, the spec and the model's compilation are not
        counted; the search, the stored graph and the property passes are) over the states.
        Fixed costs (arrays' initial capacity, 4 KiB pages) weigh most on tiny models, where
        `store_bytes_per_state` is the per-state cost."""
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
            check_liveness: bool = True, use_native: bool | None = None, workers: int = 1) -> Result:
    """Explore every reachable state; stop at the first safety violation. `use_native`: True
    compiles the model for C at once, False never, None from NATIVE_AFTER states (see _search).
    `workers` > 1: the compiled search on that many threads (model_check.parallel: the same
    store, so the same result); without a compiled model the search stays on one thread."""
    comp = compiled or compile_model(model)
    res = Result(model=model, compiled=comp, coverage=[0] * len(model.rules))
    if model.symmetry and model.responses and check_liveness:
        res.warnings.append("symmetry reduction is sound for safety only: liveness results on the "
                            "reduced graph are not a proof")
    if use_native is not False:
        # the model's C source and its digest (native.Builder.lib) are its compilation, as
        # compile_model's Python is: made before the meter starts, not counted as the search's
        # memory (150 kB of text for reaction, up to 0.5 MB resident while it is built and hashed)
        comp.native.cached()
    meter = Meter()
    bar = Progress(model.name) if progress else None
    t0, c0 = time.perf_counter(), time.process_time()
    store = StateStore(comp.layout.total_bits, len(model.rules))
    store.add_initial(comp.init)
    res.layer_starts = [0, 1]
    res.rounds = parallel.Rounds() if workers > 1 else None
    hit, hit_id, res.native = _search(model, comp, store, res.layer_starts, bar, res.times, use_native, workers,
                                      res.rounds)
    if workers > 1 and res.native is None:
        res.warnings.append(f"--workers {workers}: no compiled model (no C compiler, or a construct the C "
                            "generator does not translate): searched on one thread")
    res.store_bytes = store.nbytes         # before finish drops the hash table: the search's peak
    store.finish()
    res.store = store
    res.seconds = time.perf_counter() - t0
    # CPU seconds: comparable on a busy machine
    res.times = {"search": time.process_time() - c0 - res.times.pop("compile, in process", 0.0), **res.times}
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


def _search(model: Model, comp: Compiled, store: StateStore, layer_starts: list[int], bar: Progress | None,
            times: dict[str, float], use_native: bool | None, workers: int = 1,
            rounds: parallel.Rounds | None = None) -> tuple[tuple | None, int, Native | None]:
    """Breadth-first layers; (hit, id of the hit state, the compiled model used or None), hit None
    and id -1 when there is none.

    The compiled C search (model_check.native) runs from the first state when its shared object
    is in the cache or `use_native` is True, else once the search has NATIVE_AFTER states (a small
    model never waits for a compiler run); before that, and without a compiler or with
    `use_native` False, the generated Python `edges`. Both give the same ids, parents, edges and
    hits, so where the switch happens changes no result. Generating and compiling the C is timed
    apart ("compile", own and compiler CPU), not as search: SPIN's pan.c compile is not its search."""
    frontier: list[int] = [comp.init]
    lo, nat, tried = 0, None, use_native is False
    while True:
        if not tried:
            before, own = _cpu(), time.process_time()
            if use_native or len(store) >= NATIVE_AFTER or comp.native.cached():  # type: ignore[attr-defined]
                tried, nat = True, comp.native()
            times["compile"] = times.get("compile", 0.0) + _cpu() - before
            # explore takes this off the search
            times["compile, in process"] = times.get("compile, in process", 0.0) + time.process_time() - own
        if nat is not None and rounds is not None:
            return (*parallel.search(model, store, lo, nat, workers,
                                     lambda first, width: _next_layer(store, layer_starts, bar, first, width),
                                     rounds), nat)
        if nat is not None:           # breadth-first order is id order: the layer is ids lo .. len-1
            return (*_search_native(model, store, lo, nat, layer_starts, bar), nat)
        hi = len(store)
        frontier, hit = _layer_python(comp, store, frontier, lo)
        if hit is not None:
            return (*hit, nat)
        lo = hi
        if len(store) == hi:
            return None, -1, nat
        _next_layer(store, layer_starts, bar, lo, len(store) - hi)


def _search_native(model: Model, store: StateStore, lo: int, nat: Native, layer_starts: list[int],
                   bar: Progress | None) -> tuple[tuple | None, int]:
    """The rest of the search from the layer of ids lo .. len(store)-1 with the compiled search,
    straight into the store, a call at a time (a call goes on over layers and stops when the
    arrays are full): (hit, hit id) or (None, -1)."""
    i, stop = lo, len(store)
    while True:
        got = nat.bfs(store, i, stop, model)
        i = got.done
        for end in got.layers:           # the layers this call began (the ones before ended in it)
            _next_layer(store, layer_starts, bar, stop, end - stop)
            stop = end
        if got.kind == HIT_RANGE:
            raise RangeError(got.message)
        if got.hit() is not None:
            return got.hit(), i
        if i == stop == len(store):
            return None, -1


def _cpu() -> float:
    """CPU seconds of this process and its finished children (the C compiler)."""
    t = os.times()
    return t.user + t.system + t.children_user + t.children_system


def _layer_python(comp: Compiled, store: StateStore, frontier: list[int], lo: int):
    """One layer with the generated Python `edges`: (next frontier, None) or (_, (hit, hit id))."""
    new: list[int] = []
    # a wide layer goes in slices: the successor lists and their dedup dicts are the search's
    # biggest Python objects; slicing changes nothing (the table dedups across slices, and ids,
    # parents and the next frontier come out in the same first-seen order)
    for a in range(0, len(frontier), SLICE):
        nxt: list[int] = []
        rules: list[int] = []
        ends: list[int] = []
        hit = comp.edges(frontier[a:a + SLICE], nxt, rules, ends)
        new += store.add_layer(lo + a, nxt, rules, ends)
        if hit is not None:
            return new, (hit, lo + a + len(ends))
    return new, None


def _next_layer(store: StateStore, layer_starts: list[int], bar: Progress | None, lo: int, width: int) -> None:
    if width:
        layer_starts.append(lo + width)
    if bar:
        bar.update(len(layer_starts) - 2, len(store), width)


def _final_checks(res: Result) -> None:
    """Python-only checks (e.g. an oracle) on every state satisfying the model's `final`.

    With a `final_view`, a check sees only the view's values; with a `final_screen` too, the views
    of all final states are computed on the stored graph in bulk (numpy) and screened at once, and
    only the flagged states go through the checks, in id order: the first violation is at the
    state a check of every final state in id order finds (issue 12: no second pass in Python)."""
    comp, model, store = res.compiled, res.model, res._graph()
    final = store.mask(comp.layout, model.defs, model.final)
    final[res.layer_starts[-1]:] = False
    if not model.final_view:
        for i in final.nonzero()[0].tolist():
            if _final_violation(res, comp.layout.unpack(store.state(i)), i):
                return
        return
    names = [name for name, _ in model.final_view]
    texts = [text for _, text in model.final_view]
    for lo, hi, values in store.evaluate(comp.layout, model.defs, texts, chunk=1 << 16):   # 40 columns: small chunks
        ids = np.flatnonzero(final[lo:hi])
        if not ids.size:
            continue
        view = {n: np.broadcast_to(np.asarray(v, np.int64), (hi - lo,))[ids] for n, v in zip(names, values)}
        flagged = np.flatnonzero(model.final_screen(view)) if model.final_screen else range(len(ids))
        for j in flagged:
            if _final_violation(res, {n: int(view[n][j]) for n in names}, lo + int(ids[j])):
                return
            if model.final_screen:
                raise RuntimeError(f"{model.name}: the final screen flags state {lo + int(ids[j])}, "
                                   "the final checks pass it")


def _final_violation(res: Result, values: dict[str, int], i: int) -> bool:
    """Run the final checks on `values` (of state `i`); record the first problem as the violation."""
    for name, check in res.model.final_checks:
        problem = check(values)
        if problem:
            store = res._graph()
            res.violation = Violation("final-check", name,
                                      concretise(res.compiled, store.states(store.path_to(i))), detail=problem)
            return True
    return False


def depth_of(res: Result, state: int) -> int:
    i = res._graph().index_of(state)
    return max(d for d, start in enumerate(res.layer_starts) if start <= i)


def trace_to(res: Result, target: int, depth: int | None = None) -> list[Step]:
    """A shortest trace from the initial state to the canonical `target`, as concrete states.

    The breadth-first parent of a state is the first state of the layer before that has an
    edge to it, so this is the same trace a search of the layers for predecessors gives."""
    store = res._graph()
    return concretise(res.compiled, store.states(store.path_to(store.index_of(target))))
