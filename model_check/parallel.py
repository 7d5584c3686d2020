"""The compiled breadth-first search on several threads over one store (issue 12, item 4).

As TLC's workers do, the threads share one visited set (the store's hash table,
storage.StateStore) and split the states to expand; unlike a partition of the states
by hash (SPIN's multi-core), no successors travel between workers, and the search
writes the same store as the one-thread `bfs` (model_check.native), so responses,
final checks and counterexamples run on it unchanged. The search goes in rounds, all
in C (native.py `prun`, called on every thread; the threads meet at barriers in C):

1. thread 0 settles the last round and cuts the next stored states (they may run on into the
   next layer) into consecutive slices, SLICES per thread; in each step below the threads take
   the slices as they come free, so a thread held up by other load holds the round up less;
2. each slice is expanded against the table as it is (read only): an edge to a
   stored state gets its id; a successor not stored becomes a candidate of the slice,
   deduplicated in the slice's own table;
3. each slice in turn (one step: a slice waits for the one before it to have its base): a
   candidate an earlier slice has too is that slice's; the others are new, numbered in
   first-seen order, and get ids after the stored states and the new ones of the slices
   before, so ids, parents (the source of a state's first edge) and edges are those of the
   one-thread search; rows, parents, table slots (compare-and-swap) and edges are written by
   all threads at once.

The threads meet at three barriers a round (a short spin, then a futex sleep: a thread waiting
for one that other load holds up gives its core away).

A slice that fills its buffers (or holds a hit) ends the round there: the slices after it
are expanded again in the next round. Only the hash table's slot order may differ from the
one-thread search's (it is dropped after the search); tests/model_check/test_parallel.py
compares everything else. Python sees the search every ROUNDS rounds (progress), at its
end, at a hit, and to grow the arrays.
"""
from __future__ import annotations

import ctypes
from dataclasses import dataclass
from concurrent.futures import ThreadPoolExecutor
from typing import Callable

import numpy as np

from model_check.compile import RangeError
from model_check.gcl import Model
from model_check.native import HIT_RANGE, Native, range_message, _hit, _Res
from model_check.storage import LOAD, StateStore

NARROW = 1 << 11         # a frontier of at most this many states is expanded on one thread
EDGES = 1 << 16          # edges a slice holds at most (its buffers: about 60 bytes each)
SLICES = 2               # slices per thread in a round: the threads take them as they come free
ROUNDS = 64              # rounds between returns to Python (the progress line)
P_RUN, P_DONE, P_PAUSE, P_GROW, P_HIT = range(5)      # native.py `prun`'s status


@dataclass
class Rounds:
    """What the threads of a search did (for tests and the bench)."""

    rounds: int = 0              # rounds (each: expand, mark, insert on every thread)
    split: int = 0               # rounds with more than one slice of states
    dropped: int = 0             # rounds where a slice stopped early (full buffers, a hit): the slices
                                 # after it were expanded in vain, and again in the next round


class _CSlice(ctypes.Structure):
    _fields_ = ([(f, ctypes.c_void_p) for f in ("ev", "er", "crow", "cpar", "chash", "cslot", "cstep", "clocal",
                                                  "ltable", "cown", "cidx")]
                + [(f, ctypes.c_int64) for f in ("lbits", "a", "b", "edge0", "fresh", "base", "kept", "ready")]
                + [("r", _Res)])


class _Ctx(ctypes.Structure):
    _fields_ = ([(f, ctypes.c_void_p) for f in ("keys", "parent", "table", "dst", "rules", "degree")]
                + [(f, ctypes.c_int64) for f in ("width", "tbits", "tlimit", "kcap", "ecap", "dcap", "nk", "ne", "i",
                                                  "workers", "edges_max", "narrow", "fan", "seen_states",
                                                  "seen_edges", "rounds", "status", "cap", "bcount", "bsense", "nrounds",
                                                  "nsplit", "ndropped", "nslices", "cexp", "cmark", "bsleep")]
                + [("hit", _Res)])


class _Slice:
    """One thread's buffers (numpy, kept alive here; C sees them through `_CSlice`)."""

    def __init__(self, store: StateStore, edges: int, c: _CSlice):
        self.arrays = {
            "ev": np.empty(edges, np.int32),                 # per edge: the id, or -1 - candidate
            "er": np.empty(edges, store.rule.data.dtype),    # per edge: the rule
            "crow": np.empty((edges, store.width), np.uint8),  # per candidate: the state's row
            "cpar": np.empty(edges, np.int32),                # ... the source of its first edge
            "chash": np.empty(edges, np.uint64),              # ... its hash
            "cslot": np.empty(edges, np.int64),               # ... where its probe of the table stopped
            "cstep": np.empty(edges, np.int64),
            "clocal": np.empty(edges, np.int32),              # ... its slot in `ltable`
            "ltable": np.full(1 << (2 * edges - 1).bit_length(), -1, np.int32),   # the slice's own table
            "cown": np.empty(edges, np.int32),                # ... the first slice that has it
            "cidx": np.empty(edges, np.int32),                # ... its number there
        }
        for name, a in self.arrays.items():
            setattr(c, name, a.ctypes.data)
        c.lbits = (2 * edges - 1).bit_length()


def search(model: Model, store: StateStore, lo: int, nat: Native, workers: int,
           on_layer: Callable[[int, int], None], rounds: Rounds) -> tuple[tuple | None, int]:
    """`engine._search_native` on `workers` threads: the search from the layer of ids
    lo .. len(store)-1 into `store`; (hit, hit id) or (None, -1). `on_layer(first id, width)`
    is called as each new layer begins; `rounds` counts what the threads did."""
    prun = nat.lib.prun
    prun.restype = None
    edges = max(EDGES, nat.n_rules)              # room for one state's successors at least
    nslices = workers * SLICES
    csl = (_CSlice * nslices)()
    slices = [_Slice(store, edges, csl[t]) for t in range(nslices)]      # noqa: F841 - the buffers C uses
    ctx = _Ctx(workers=workers, nslices=nslices, width=store.width, edges_max=edges, narrow=NARROW,
               fan=nat.n_rules, i=lo)
    stop = len(store)
    room = nslices * nat.n_rules
    with ThreadPoolExecutor(workers - 1) as pool:
        store.rehash = lambda keys, table, bits: _rehash(nat, pool, workers, keys, table, bits)
        while True:
            _bind(ctx, store)
            ctx.status, ctx.rounds, ctx.bcount, ctx.bsense, ctx.bsleep = P_RUN, ROUNDS, 0, 0, 0
            _on_threads(pool, prun, [(ctypes.byref(ctx), csl, ctypes.c_int64(t)) for t in range(workers)])
            rounds.rounds, rounds.split, rounds.dropped = ctx.nrounds, ctx.nsplit, ctx.ndropped
            store.keys.n = store.parent.n = ctx.nk
            store.dst.n = store.rule.n = ctx.ne
            store.degree.n = i = ctx.i
            stop = _layers(store, stop, i, on_layer)
            if ctx.status == P_DONE:
                return None, -1
            if ctx.status == P_HIT:
                h = ctx.hit
                if h.kind == HIT_RANGE:
                    raise RangeError(range_message(model, int(h.rule), int(h.var), int(h.value)))
                return _hit(int(h.kind), int(h.index), None), i
            if ctx.status == P_GROW:             # what a round may need at most; the table as `bfs` grows it
                if int(LOAD * len(store.table)) - len(store) < room:     # type: ignore[arg-type]
                    store.reserve(room, 0, 0)
                for g in (store.keys, store.parent, store.dst, store.rule, store.degree):
                    g.reserve(nslices * edges)


def _rehash(nat: Native, pool: ThreadPoolExecutor, workers: int, keys: np.ndarray, table: np.ndarray,
            bits: int) -> None:
    """`Native.rehash` on all the threads (the serial rehash was 6.6% of a two-thread profile):
    each empties a part of the slots of `table` (not yet set: np.empty, so its pages are first
    touched here, on the threads), then, once all are empty, puts a part of the stored rows."""
    p, n64 = ctypes.c_void_p, ctypes.c_int64
    slots = [len(table) * t // workers for t in range(workers + 1)]
    _on_threads(pool, nat.lib.pfill, [(p(table.ctypes.data), n64(slots[t]), n64(slots[t + 1]))
                                      for t in range(workers)])
    cuts = [len(keys) * t // workers for t in range(workers + 1)]
    _on_threads(pool, nat.lib.prehash, [(p(keys.ctypes.data), n64(cuts[t]), n64(cuts[t + 1]),
                                         p(table.ctypes.data), n64(bits)) for t in range(workers)])


def _on_threads(pool: ThreadPoolExecutor, fn, args: list[tuple]) -> None:
    """`fn(*args[t])` on thread t of the search (0: this one), until all have returned."""
    fn.restype = None
    futures = [pool.submit(fn, *a) for a in args[1:]]
    fn(*args[0])
    for f in futures:
        f.result()


def _bind(ctx: _Ctx, store: StateStore) -> None:
    """The store's arrays (they move as they grow) and counts, for `prun`."""
    for name, g in (("keys", store.keys), ("parent", store.parent), ("dst", store.dst), ("rules", store.rule),
                    ("degree", store.degree)):
        setattr(ctx, name, g.data.ctypes.data)
    ctx.table = store.table.ctypes.data         # type: ignore[union-attr]
    ctx.tbits, ctx.tlimit = store.table_bits, int(LOAD * len(store.table))   # type: ignore[arg-type]
    ctx.kcap = min(len(store.keys.data), len(store.parent.data))
    ctx.ecap = min(len(store.dst.data), len(store.rule.data))
    ctx.dcap = len(store.degree.data)
    ctx.nk, ctx.ne = len(store), store.dst.n


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
