"""Breadth-first safety search on several cores with a partitioned visited set (issue 12, item 4).

As in SPIN's multi-core mode and TLC's workers, every state has an owner: worker
`mix64(state) % workers`. A worker keeps the visited set of its own states only
(storage.StateStore used as a bare set: keys and hash table, no graph), expands the
new states it owns with the generated `edges` function, and sends each successor to
its owner. The layers are synchronised: the coordinating process relays the
successor batches (as opaque pickled bytes) once every worker has finished a
layer, so layer k of every worker holds exactly the states at distance k. The
union of the layers, the edges expanded, the depth and the rule coverage are
therefore those of the sequential search, and so is the verdict: every state is
checked against the invariants and for deadlock when it is expanded, in both.

What it does not do: the response bounds and weak-fairness checks, and the models'
final-state checks, need the stored graph (model_check.engine); a parallel run
reports them as not checked. A violation's shortest trace is recomputed by the
sequential search, which stops at the same layer.
"""
from __future__ import annotations

import multiprocessing as mp
import pickle
import resource
import time
from dataclasses import dataclass

import numpy as np

from model_check.compile import Compiled, RangeError, compile_model
from model_check.engine import SLICE, Progress, Result, explore
from model_check.native import HIT_RANGE, Native
from model_check.gcl import Model
from model_check.storage import Meter, StateStore, mix64


@dataclass
class _Layer:
    """What a worker reports after expanding one layer."""

    new: int                      # states of this layer it owns
    edges: int                    # transitions it expanded
    coverage: np.ndarray          # per rule
    hit: tuple | None             # (kind, index, state) of a violation found, or None


def _owners(store: StateStore, states: list[int], workers: int) -> np.ndarray:
    return (mix64(store.to_words(states)) % np.uint64(workers)).astype(np.int64)


def _worker(me: int, workers: int, model: Model, comp: Compiled, conn, nat: Native | None = None) -> None:
    """One partition: dedup what arrives, expand what is new, ship successors to their owners.
    States travel as uint64 word rows with the C successor function (`nat`), as ints without."""
    meter = Meter()
    rules = len(model.rules)
    store = StateStore(comp.layout.total_bits, rules)
    init = store.to_words([comp.init])
    mine = int((mix64(init) % np.uint64(workers))[0]) == me
    incoming: list[int] | np.ndarray = (init if mine else init[:0]) if nat else ([comp.init] if mine else [])
    while True:
        if nat is None:
            new: list[int] | np.ndarray = store.add_states(incoming)
            nxt, rule, ends = [], [], []
            hit = comp.edges(new, nxt, rule, ends) if new else None
            edges, cov, out = len(nxt), np.bincount(np.asarray(rule, np.int64), minlength=rules), nxt
            owner = _owners(store, nxt, workers) if nxt else np.zeros(0, np.int64)
            buckets = [[nxt[i] for i in np.flatnonzero(owner == j).tolist()] for j in range(workers)]
        else:
            new = store.add_rows(incoming)
            out, edges, cov, hit = _expand_rows(model, nat, new, rules)
            owner = (mix64(out) % np.uint64(workers)).astype(np.int64)
            buckets = [out[owner == j] for j in range(workers)]
        conn.send(_Layer(len(new), edges, cov, hit))
        for j in range(workers):
            if j != me:
                conn.send_bytes(pickle.dumps(buckets[j], pickle.HIGHEST_PROTOCOL))
        if not conn.recv():                       # the coordinator says stop
            conn.send((meter.peak(), store.nbytes))
            conn.close()
            return
        parts = [buckets[me]] + [pickle.loads(conn.recv_bytes()) for j in range(workers) if j != me]
        incoming = np.concatenate(parts) if nat else [s for part in parts for s in part]


def _expand_rows(model: Model, nat: Native, new: np.ndarray, rules: int):
    """A worker's layer on the C successor function: (distinct successors of each call, edges,
    coverage, hit) -- up to the first violation, like the Python `edges`."""
    outs, edges, cov, a = [], 0, np.zeros(rules, np.int64), 0
    while a < len(new):
        chunk = nat.expand(new[a:a + SLICE])
        outs.append(chunk.distinct)
        edges += len(chunk.inv)
        cov += np.bincount(chunk.rules, minlength=rules)
        a += chunk.done
        if chunk.kind == HIT_RANGE:
            raise RangeError(chunk.range_message(model))
        if chunk.hit() is not None:
            return np.concatenate(outs), edges, cov, chunk.hit(int.from_bytes(new[a].astype("<u8").tobytes(), "little"))
    return (np.concatenate(outs) if outs else new[:0]), edges, cov, None


def explore_parallel(model: Model, workers: int = 2, compiled: Compiled | None = None,
                     progress: bool = True) -> Result:
    """The sequential search's states, transitions, depth, coverage and safety verdict, on
    `workers` processes (fork: the compiled model is inherited, not pickled)."""
    comp = compiled or compile_model(model)
    res = Result(model=model, compiled=comp, coverage=[0] * len(model.rules))
    if model.responses or model.final_checks:
        res.warnings.append(f"parallel search ({workers} workers) checks invariants and deadlocks only: "
                            "responses and final-state checks need the stored graph (run without --workers)")
    meter = Meter()
    bar = Progress(model.name) if progress else None
    t0, c0, ch0 = time.perf_counter(), time.process_time(), _children_cpu()
    nat = comp.native()            # compiled once, before the fork: every worker inherits it
    ctx = mp.get_context("fork")
    conns, procs = [], []
    for w in range(workers):
        mine, theirs = ctx.Pipe()
        p = ctx.Process(target=_worker, args=(w, workers, model, comp, theirs, nat), daemon=True)
        p.start()
        theirs.close()
        conns.append(mine)
        procs.append(p)
    cov = np.zeros(len(model.rules), np.int64)
    layers, hit = 0, None
    try:
        while True:
            reports, batches = [], []
            for w, conn in enumerate(conns):
                reports.append(conn.recv())
                batches.append({j: conn.recv_bytes() for j in range(workers) if j != w})
            new = sum(r.new for r in reports)
            res.states += new
            res.transitions += sum(r.edges for r in reports)
            cov += sum(r.coverage for r in reports)
            layers += 1 if new else 0
            hit = next((r.hit for r in reports if r.hit is not None), None)
            go = new > 0 and hit is None
            for j, conn in enumerate(conns):
                conn.send(go)
                if go:
                    for w in range(workers):
                        if w != j:
                            conn.send_bytes(batches[w][j])
            if bar:
                bar.update(layers - 1, res.states, new)
            if not go:
                break
        finals = [conn.recv() for conn in conns]            # (resident peak, visited-set bytes)
    finally:
        for conn in conns:
            conn.close()
        for p in procs:
            p.join(timeout=10)
            if p.is_alive():                     # pragma: no cover - only after an error above
                p.terminate()
    res.depth = max(layers - 1, 0)
    res.coverage = cov.tolist()
    res.seconds = time.perf_counter() - t0
    res.peak_bytes = meter.peak() + sum(peak for peak, _ in finals)   # the coordinator and every worker
    res.store_bytes = sum(size for _, size in finals)
    res.cpu = time.process_time() - c0 + _children_cpu() - ch0     # workers: RUSAGE_CHILDREN
    res.times["search"] = res.cpu
    if hit is not None:
        # the sequential search stops in the same layer and gives the shortest trace
        seq = explore(model, comp, progress=False, check_liveness=False)
        res.violation = seq.violation
        res.warnings.append("state and transition counts of a failing parallel run cover whole layers: "
                            "the sequential search stops inside the layer of the first violation")
    return res


def _children_cpu() -> float:
    ru = resource.getrusage(resource.RUSAGE_CHILDREN)
    return ru.ru_utime + ru.ru_stime
