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

EDGES = 1 << 17          # edges a thread expands in one round at most (its buffers: about 60 bytes each)


class _Slice:
    """One thread's buffers for a round (reused): its edges and its candidates."""

    def __init__(self, store: StateStore, edges: int):
        self.ev = np.empty(edges, np.int32)                  # per edge: the id, or -1 - candidate
        self.er = np.empty(edges, store.rule.data.dtype)     # per edge: the rule
        self.crow = np.empty((edges, store.width), np.uint8)  # per candidate: the state's row
        self.cpar = np.empty(edges, np.int32)                 # ... the source of its first edge
        self.cslot = np.empty(edges, np.int64)                # ... where its probe stopped
        self.cstep = np.empty(edges, np.int64)
        self.clocal = np.empty(edges, np.int32)               # ... its slot in `ltable`
        self.cmap = np.empty(edges, np.int32)                 # ... its id (step 2)
        self.lbits = (2 * edges - 1).bit_length()
        self.ltable = np.full(1 << self.lbits, -1, np.int32)
        self.res = _Res()
        self.a = self.b = 0                                   # the states of this round

    def ptr(self, name: str) -> ctypes.c_void_p:
        return ctypes.c_void_p(getattr(self, name).ctypes.data)


def search(model: Model, store: StateStore, lo: int, nat: Native, workers: int,
           on_layer: Callable[[int, int], None]) -> tuple[tuple | None, int]:
    """`engine._search_native` on `workers` threads: the search from the layer of ids
    lo .. len(store)-1 into `store`; (hit, hit id) or (None, -1). `on_layer(first id, width)`
    is called as each new layer begins."""
    lib, p, n64 = nat.lib, ctypes.c_void_p, ctypes.c_int64
    lib.pexpand.restype = lib.pfix.restype = None
    lib.pmerge.restype = ctypes.c_int64
    store.rehash = nat.rehash
    room_min = workers * nat.n_rules             # a round expands at least one state per thread
    slices = [_Slice(store, EDGES) for _ in range(workers)]
    fan = nat.n_rules                            # successors per state, for the round's size: the worst at first
    seen_states = seen_edges = 0
    i, stop = lo, len(store)

    def expand(s: _Slice) -> None:
        lib.pexpand(n64(s.a), n64(s.b), p(store.keys.data.ctypes.data), n64(store.width),
                    p(store.table.ctypes.data), n64(store.table_bits), n64(cap), s.ptr("ev"), s.ptr("er"),
                    s.ptr("crow"), s.ptr("cpar"), s.ptr("cslot"), s.ptr("cstep"), s.ptr("clocal"), s.ptr("ltable"),
                    n64(s.lbits), p(store.degree.data.ctypes.data), ctypes.byref(s.res))

    def fix(s: _Slice, edge0: int, keep: bool) -> None:
        ne = int(s.res.edges) if keep else 0    # a slice not kept only empties its table
        lib.pfix(n64(ne), s.ptr("ev"), s.ptr("er"), s.ptr("cmap"), n64(s.res.distinct), s.ptr("clocal"),
                 s.ptr("ltable"), p(store.dst.data[edge0:].ctypes.data), p(store.rule.data[edge0:].ctypes.data))

    with ThreadPoolExecutor(workers - 1) as pool:
        while True:
            if i == stop:                        # the layer is done: the next is the states it found
                if len(store) == stop:
                    return None, -1
                on_layer(stop, len(store) - stop)
                stop = len(store)
            if int(LOAD * len(store.table)) - len(store) < room_min:     # type: ignore[arg-type]
                store.reserve(room_min, 0, 0)    # the table grows (as `bfs`'s caller grows it)
            cap = min(EDGES, (int(LOAD * len(store.table)) - len(store)) // workers)   # type: ignore[arg-type]
            per = max(1, min(-(-(stop - i) // workers), cap // fan))
            for w, s in enumerate(slices):
                s.a = min(stop, i + w * per)
                s.b = min(stop, s.a + per)
            store.degree.reserve(slices[-1].b - store.degree.n)
            _run(pool, expand, slices)
            # keep the slices up to the first that stopped early (full buffers or a hit)
            kept: list[_Slice] = []
            for s in slices:
                if s.a == s.b:
                    break
                kept.append(s)
                if s.res.done < s.b:
                    break
            cands = sum(int(s.res.distinct) for s in kept)
            edges = sum(int(s.res.edges) for s in kept)
            for g in (store.keys, store.parent):
                g.reserve(cands)
            for g in (store.dst, store.rule):
                g.reserve(edges)
            nk = len(store)
            for s in kept:
                nk = lib.pmerge(n64(s.res.distinct), s.ptr("crow"), s.ptr("cpar"), s.ptr("cslot"), s.ptr("cstep"),
                                s.ptr("cmap"), p(store.keys.data.ctypes.data), n64(nk), n64(store.width),
                                p(store.parent.data.ctypes.data), p(store.table.ctypes.data), n64(store.table_bits))
            edge0 = [store.dst.n]
            for s in kept:
                edge0.append(edge0[-1] + int(s.res.edges))
            _run(pool, lambda s: fix(s, edge0[slices.index(s)] if s in kept else 0, s in kept), slices)
            last = kept[-1].res
            store.keys.n = store.parent.n = nk
            store.dst.n = store.rule.n = edge0[-1]
            store.degree.n = i = int(last.done)
            seen_states += i - slices[0].a
            seen_edges += edges
            fan = max(1, min(nat.n_rules, -(-2 * seen_edges // max(seen_states, 1))))
            if last.kind == HIT_RANGE:
                raise RangeError(range_message(model, int(last.rule), int(last.var), int(last.value)))
            if last.kind not in (HIT_NONE, HIT_FULL):
                return _hit(int(last.kind), int(last.index), None), i


def _run(pool: ThreadPoolExecutor, fn: Callable[[_Slice], None], slices: list[_Slice]) -> None:
    """fn on every slice at once: the first in this thread, the others on the pool."""
    futures = [pool.submit(fn, s) for s in slices[1:]]
    fn(slices[0])
    for f in futures:
        f.result()
