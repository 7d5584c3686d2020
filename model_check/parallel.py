"""The compiled breadth-first search on several threads over one store (issue 12, item 4).

As TLC's workers do, the threads share one visited set (the store's hash table,
storage.StateStore) and split the layer being expanded; unlike a partition of the
states by hash (SPIN's multi-core), this needs no exchange of successors between
workers, and the search writes the same store as the sequential `bfs`
(model_check.native), so responses, final checks and counterexamples run on it
unchanged. A layer goes in rounds, each of three steps in C (native.py `_PARALLEL`):

1. every thread expands its consecutive slice of the round's states against the table as
   it is (read only): an edge to a stored state gets its id; a successor not stored becomes
   a candidate of that thread, deduplicated in the thread's own table;
2. one thread puts the candidates into the shared table, slice after slice, each from where
   its probe stopped: new states get ids in first-seen order, their parent is the source of
   their first edge (the slices are consecutive, so their edges are in the sequential order);
3. every thread turns its edges' candidate numbers into ids and copies them to their place.

So ids, parents, edges, degrees and even the hash table are the sequential search's, byte for
byte (tests/model_check/test_parallel.py compares the stores), and so are the counts, bounds,
verdicts and traces. ctypes lets go of the GIL in each call, so the C steps run on both cores;
step 2 is serial (one probe and one row copy per new state: about a third of the edges).
"""
from __future__ import annotations

import ctypes
from concurrent.futures import ThreadPoolExecutor
from typing import Callable

import numpy as np

from model_check.compile import RangeError
from model_check.gcl import Model
from model_check.native import HIT_FULL, HIT_NONE, HIT_RANGE, Native, range_message, _hit, _Res
from model_check.storage import LOAD, StateStore

NARROW = 1 << 11         # a frontier of at most this many states is expanded on one thread
EDGES = 1 << 17          # edges a thread expands in one round at most (its buffers: about 60 bytes each)


class _Slice:
    """One thread's buffers for a round (reused): its edges and its candidates."""

    def __init__(self, store: StateStore, edges: int):
        self.ev = np.empty(edges, np.int32)                  # per edge: the id, or -1 - candidate
        self.er = np.empty(edges, store.rule.data.dtype)     # per edge: the rule
        self.crow = np.empty((edges, store.width), np.uint8)  # per candidate: the state's row
        self.cpar = np.empty(edges, np.int32)                 # ... the source of its first edge
        self.chash = np.empty(edges, np.uint64)               # ... its hash
        self.cslot = np.empty(edges, np.int64)                # ... where its probe stopped
        self.cstep = np.empty(edges, np.int64)
        self.clocal = np.empty(edges, np.int32)               # ... its slot in `ltable`
        self.cown = np.empty(edges, np.int32)                 # ... the first slice that has it
        self.cidx = np.empty(edges, np.int32)                 # ... its number there
        self.lbits = (2 * edges - 1).bit_length()
        self.ltable = np.full(1 << self.lbits, -1, np.int32)
        self.res = _Res()
        self.a = self.b = 0                                   # the states of this round
        self.edge0 = 0                                        # where its edges go in the store
        # the buffers never move: their addresses once (numpy's .ctypes costs microseconds a time)
        self.ptr = {name: ctypes.c_void_p(getattr(self, name).ctypes.data)
                    for name in ("ev", "er", "crow", "cpar", "chash", "cslot", "cstep", "clocal", "cown", "cidx",
                                               "ltable")}


def search(model: Model, store: StateStore, lo: int, nat: Native, workers: int,
           on_layer: Callable[[int, int], None]) -> tuple[tuple | None, int]:
    """`engine._search_native` on `workers` threads: the search from the layer of ids
    lo .. len(store)-1 into `store`; (hit, hit id) or (None, -1). `on_layer(first id, width)`
    is called as each new layer begins."""
    lib, p, n64 = nat.lib, ctypes.c_void_p, ctypes.c_int64
    lib.pexpand.restype = None
    lib.pmark.restype = ctypes.c_int64
    lib.pinsert.restype = None
    store.rehash = nat.rehash
    room_min = workers * nat.n_rules             # a round expands at least one state per thread
    slices = [_Slice(store, EDGES) for _ in range(workers)]
    fan = nat.n_rules                            # successors per state, for the round's size: the worst at first
    seen_states = seen_edges = 0
    i, stop = lo, len(store)

    crows, ltables, cidxs = ((ctypes.c_void_p * workers)(*(s.ptr[name] for s in slices))
                             for name in ("crow", "ltable", "cidx"))
    base = np.zeros(workers, np.int64)             # per slice: the id of its first new state
    fresh = [0] * workers                          # per slice: its new states

    def expand(s: _Slice) -> None:
        lib.pexpand(n64(s.a), n64(s.b), keys, n64(store.width), table, n64(store.table_bits), n64(cap),
                    s.ptr["ev"], s.ptr["er"], s.ptr["crow"], s.ptr["cpar"], s.ptr["chash"], s.ptr["cslot"],
                    s.ptr["cstep"], s.ptr["clocal"], s.ptr["ltable"], n64(s.lbits), degree, ctypes.byref(s.res))

    def mark(s: _Slice) -> None:
        t = slices.index(s)
        fresh[t] = lib.pmark(n64(t), n64(s.res.distinct), s.ptr["crow"], s.ptr["chash"], n64(store.width),
                             n64(s.lbits), crows, ltables, s.ptr["cown"], s.ptr["cidx"])

    def insert(s: _Slice) -> None:
        t = slices.index(s)
        lib.pinsert(n64(t), n64(s.res.distinct), s.ptr["crow"], s.ptr["cpar"], s.ptr["cslot"], s.ptr["cstep"],
                    s.ptr["cown"], s.ptr["cidx"], cidxs, p(base.ctypes.data), keys, n64(store.width), parent,
                    table, n64(store.table_bits), n64(s.res.edges), s.ptr["ev"], s.ptr["er"], s.ptr["clocal"],
                    s.ptr["ltable"], p(dst + s.edge0 * 4), p(rule + s.edge0 * store.rule.data.itemsize))

    with ThreadPoolExecutor(workers - 1) as pool:
        while True:
            if i == len(store):
                return None, -1
            if int(LOAD * len(store.table)) - len(store) < room_min:     # type: ignore[arg-type]
                store.reserve(room_min, 0, 0)    # the table grows (as `bfs`'s caller grows it)
            cap = max(nat.n_rules, min(EDGES, (int(LOAD * len(store.table)) - len(store)) // workers))  # type: ignore
            # a round may run on into the states of the next layer that are stored already; a narrow
            # frontier (the first and last layers) goes to one thread: no hand-over to wait for
            end = len(store)
            per = max(1, min(-(-(end - i) // workers) if end - i > NARROW else end - i, cap // fan))
            for w, s in enumerate(slices):
                s.a = min(end, i + w * per)
                s.b = min(end, s.a + per)
            store.degree.reserve(slices[-1].b - store.degree.n)
            keys, table, degree = (p(a.ctypes.data) for a in (store.keys.data, store.table, store.degree.data))
            _run(pool, expand, slices)
            # keep the slices up to the first that stopped early (full buffers or a hit)
            kept: list[_Slice] = []
            for s in slices:
                if s.a == s.b:
                    break
                kept.append(s)
                if s.res.done < s.b:
                    break
            for s in slices[len(kept):]:         # expanded in vain (or not at all): empty their tables
                s.ltable[s.clocal[:s.res.distinct]] = -1
                s.res.distinct = s.res.edges = 0
            _run(pool, mark, kept)
            nk, edges = len(store), store.dst.n
            for t, s in enumerate(kept):         # ids and edges of each slice after the slice before
                base[t], nk = nk, nk + fresh[t]
                s.edge0, edges = edges, edges + int(s.res.edges)
            for g in (store.keys, store.parent):
                g.reserve(nk - len(store))
            for g in (store.dst, store.rule):
                g.reserve(edges - store.dst.n)
            keys, parent = p(store.keys.data.ctypes.data), p(store.parent.data.ctypes.data)
            dst, rule = store.dst.data.ctypes.data, store.rule.data.ctypes.data
            _run(pool, insert, kept)
            last = kept[-1].res
            seen_states += int(last.done) - slices[0].a
            seen_edges += edges - store.dst.n
            store.keys.n = store.parent.n = nk
            store.dst.n = store.rule.n = edges
            store.degree.n = i = int(last.done)
            fan = max(1, min(nat.n_rules, -(-2 * seen_edges // max(seen_states, 1))))
            stop = _layers(store, stop, i, on_layer)
            if last.kind == HIT_RANGE:
                raise RangeError(range_message(model, int(last.rule), int(last.var), int(last.value)))
            if last.kind not in (HIT_NONE, HIT_FULL):
                return _hit(int(last.kind), int(last.index), None), i


def _layers(store: StateStore, stop: int, done: int, on_layer: Callable[[int, int], None]) -> int:
    """Report the layers that began once the states before `done` were expanded; the layer
    being expanded ends before the returned id. A new state's parent is the first state with
    an edge to it, so parents grow with ids: the layer after `stop` ends at the first state
    whose parent is not below `stop` (where `bfs`'s count was when it reached `stop`)."""
    parent = store.parent.view
    while stop <= done:
        end = stop + int(np.searchsorted(parent[stop:], stop))
        if end == stop:
            break
        on_layer(stop, end - stop)
        stop = end
    return stop


def _run(pool: ThreadPoolExecutor, fn: Callable[[_Slice], None], slices: list[_Slice]) -> None:
    """fn on every slice at once: the first in this thread, the others on the pool."""
    futures = [pool.submit(fn, s) for s in slices[1:] if s.a < s.b]
    fn(slices[0])
    for f in futures:
        f.result()
