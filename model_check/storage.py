"""Compact storage of the explored state graph (issue 12): numpy arrays, no per-state objects.

A state is the model's packed int (compile.Layout); here it is kept as
ceil(bits / 8) little-endian bytes, one row per state (17 bytes for id_retry's
129 bits, not three 64-bit words), numbered in breadth-first, first-seen order
(the state id); hashing and bit-field reads widen a slice of rows to 64-bit
words on the fly. Beside the rows:

- an open-addressing hash table of ids (int32, triangular probing, load <= 0.7),
  used while searching and dropped afterwards;
- the graph in CSR form: per state its out-degree, per edge the successor's id
  (int32) and the rule (uint8/uint16) -- so response bounds and weak-fairness
  checks run on the stored graph (model_check.liveness) instead of
  re-expanding every state;
- per state the id of its breadth-first parent, so a shortest trace is a walk
  up the parents.

The generated `edges` function (fastgen) appends every successor of a layer to
a plain list; `add_layer` deduplicates that list in bulk with numpy (sort within
the layer, then probe the table in vectorised rounds), which is where the time
per edge goes from a Python set lookup to a few numpy element operations.
About 50 bytes per state for id_retry (17 for the key, 8 for the table while
searching, ~16 for edges, 4 for the parent, 4 for the CSR offsets), against
roughly 80 for a Python set of ints alone.
"""
from __future__ import annotations

import ast
import ctypes
import ctypes.util
import functools
import mmap
import os
from itertools import repeat
from typing import Callable

import numpy as np

from model_check import expr

LOAD = 0.7                          # grow the hash table beyond this fill
REHASH = 1 << 18                    # states re-inserted per vectorised step when the table grows
COUNT = 1 << 11                     # edges per bincount in `coverage` (16 KiB of int64 at a time)
_M1 = np.uint64(0x9E3779B97F4A7C15)  # Fibonacci hashing multiplier
_M2 = np.uint64(0xBF58476D1CE4E5B9)  # splitmix64 constants, to mix the words of a key
_M3 = np.uint64(0x94D049BB133111EB)


class Meter:
    """Resident memory a check adds: the peak (VmHWM) since it started, minus VmRSS then,
    minus the file-backed pages it brought in (RssFile at the end minus at the start).

    The kernel's peak is reset at the start (/proc/self/clear_refs, Linux >= 4.0) so an
    earlier, bigger check in the same process does not count; where that is not possible
    the figure falls back to the current RSS at the end (an under-estimate of the peak).
    File-backed pages are code, not data: the first call of a numpy loop faults in 128 kB of
    numpy's shared library (RssFile +128 kB, RssAnon +4 kB, measured), the model's shared
    object is another 28 kB; on a 1,816-state model those alone were 150 of 208 bytes/state.
    Code pages stay resident for the short check, so the ones at the end were there at the peak."""

    def __init__(self) -> None:
        _trim()
        try:
            with open("/proc/self/clear_refs", "w") as fh:
                fh.write("5")
            self.reset = True
        except OSError:
            self.reset = False
        self.base, self.file = _status("VmRSS"), _status("RssFile")

    def peak(self) -> int:
        top = _status("VmHWM") if self.reset else _status("VmRSS")
        return max(0, top - self.base - max(0, _status("RssFile") - self.file))


def _trim() -> None:
    """Give the C heap's free pages back to the system (glibc malloc_trim), so that arrays of
    the check cannot hide in memory an earlier step freed and the peak counts them all."""
    try:
        _libc().malloc_trim(0)
    except (OSError, AttributeError):       # not glibc: the peak may then under-count
        pass


@functools.cache
def _libc() -> ctypes.CDLL:
    """The C library, looked up once (find_library runs ldconfig: 15 ms a time)."""
    return ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")


def _status(key: str) -> int:
    """A memory figure of this process from /proc/self/status, in bytes (0 where unavailable)."""
    try:
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith(key + ":"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return 0


class Grow:
    """An append-only numpy array grown in place by 1/4 at a time.

    From `_MAPPED` bytes its memory is a mapping of its own (`_Pages`) grown by mremap: no
    copy, so the old and the new array are never both resident (a copying doubling put one
    whole extra array on top of the peak), and no zero-fill: the new capacity becomes resident
    only as it is written, page by page, on the thread that writes it. Below that it is a
    numpy block on the C heap, which reuses memory already resident (a mapping per small
    array doubled the 1,816-state arbitration model's bytes/state, 54 -> 110). Either way
    unwritten rows read 0. A view taken before an `append`, `reserve` or `trim` is invalid
    after it (the block may have moved)."""

    def __init__(self, dtype, width: int = 0, capacity: int = 1024):
        self.width = width
        self.dtype = np.dtype(dtype)
        self._pages: _Pages | None = None
        self.data = np.zeros((capacity, width) if width else capacity, self.dtype)
        self.n = 0

    def append(self, chunk: np.ndarray) -> None:
        need = self.n + len(chunk)
        self.reserve(len(chunk))
        self.data[self.n:need] = chunk
        self.n = need

    def reserve(self, extra: int) -> None:
        """Capacity for `extra` more rows (grown by a quarter at least, as `append` does)."""
        need = self.n + extra
        if need > len(self.data):
            self._resize(max(need, len(self.data) + len(self.data) // 4))

    def trim(self) -> None:
        """Capacity down to the length (no more appends are expected; they would still work)."""
        self._resize(max(self.n, 1))

    def _resize(self, cap: int) -> None:
        shape = (cap, self.width) if self.width else (cap,)
        if self._pages is None and self._bytes(cap) < _MAPPED:
            self.data.resize(shape, refcheck=False)      # small: numpy's heap block, zero-filled
            _trim()       # a small block moves on the C heap: give back the one it left
            return
        if self._pages is None:                           # crossing into a mapping: one copy
            small, self._pages = self.data, _Pages(self._bytes(cap))
            self.data = self._pages.array(shape, self.dtype)
            self.data[:self.n] = small[:self.n]
            return
        self._pages.resize(self._bytes(cap))
        self.data = self._pages.array(shape, self.dtype)

    def _bytes(self, rows: int) -> int:
        return rows * max(self.width, 1) * self.dtype.itemsize

    @property
    def view(self) -> np.ndarray:
        return self.data[:self.n]


class _Pages:
    """Anonymous memory (mmap) that grows by mremap: no copy (page tables move) and no zero-fill
    here: a page comes zeroed from the kernel when first touched, on the thread that touches it
    (numpy's `resize` memsets the new capacity on the calling thread: the serial pause between
    rounds of the parallel search, model_check.parallel). Freed when no array views it."""

    def __init__(self, nbytes: int):
        self.nbytes = _pages(nbytes)
        addr = _mm().mmap(None, self.nbytes, _PROT_RW, _MAP_ANON, -1, 0)
        self.addr = _mapped(addr, self.nbytes)
        self._huge()

    def resize(self, nbytes: int) -> None:
        nbytes = _pages(nbytes)
        if nbytes != self.nbytes:
            self.addr = _mapped(_mm().mremap(self.addr, self.nbytes, nbytes, _MREMAP_MAYMOVE), nbytes)
            self.nbytes = nbytes
            self._huge()

    def _huge(self) -> None:
        """Transparent huge pages for a large block, as numpy asks for its own (the search probes
        rows at random: without them 1-thread id_retry ran 8% slower); only a hint."""
        if self.nbytes >= _HUGE:
            _mm().madvise(self.addr, self.nbytes, _MADV_HUGEPAGE)

    def array(self, shape: tuple[int, ...], dtype: np.dtype) -> np.ndarray:
        """The memory as an array (its base keeps this mapping alive)."""
        return np.asarray(_Window(self, shape, dtype))

    def __del__(self) -> None:
        _mm().munmap(self.addr, self.nbytes)


class _Window:
    """The array interface of a `_Pages` at its present address."""

    def __init__(self, pages: _Pages, shape: tuple[int, ...], dtype: np.dtype):
        self.pages = pages
        self.__array_interface__ = {"data": (pages.addr, False), "shape": shape, "typestr": dtype.str,
                                    "version": 3}


_PROT_RW, _MAP_ANON, _MREMAP_MAYMOVE = 0x1 | 0x2, 0x02 | 0x20, 1   # PROT_READ|WRITE, MAP_PRIVATE|ANONYMOUS
_MADV_HUGEPAGE, _HUGE = 14, 1 << 22                                  # numpy's threshold for the hint: 4 MiB
_MAPPED = 1 << 20                      # a Grow from here on is a mapping (glibc maps blocks from 128 kB-32 MB)


def _pages(nbytes: int) -> int:
    size = mmap.PAGESIZE
    return max(size, -(-nbytes // size) * size)


def _mapped(addr: int | None, nbytes: int) -> int:
    if addr is None or addr == ctypes.c_void_p(-1).value:                 # MAP_FAILED
        raise MemoryError(f"cannot map {nbytes} bytes: {os.strerror(ctypes.get_errno())}")
    return addr


@functools.cache
def _mm() -> ctypes.CDLL:
    """The C library's mmap, mremap, munmap and madvise, typed (Linux: the compiled search runs there)."""
    lib = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
    vp, sz, i = ctypes.c_void_p, ctypes.c_size_t, ctypes.c_int
    for name, args, res in (("mmap", [vp, sz, i, i, i, ctypes.c_long], vp), ("mremap", [vp, sz, sz, i], vp),
                            ("munmap", [vp, sz], i), ("madvise", [vp, sz, i], i)):
        fn = getattr(lib, name)
        fn.argtypes, fn.restype = args, res
    return lib


def mix64(rows: np.ndarray, seed: np.uint64 = np.uint64(0)) -> np.ndarray:
    """A 64-bit hash of each row of uint64 words (Fibonacci multiply, splitmix64 finaliser);
    a different `seed` gives an independent-looking second hash (bitstate's double hashing)."""
    h = (rows[:, 0] ^ seed) * _M1
    for w in range(1, rows.shape[1]):
        h = (h ^ (h >> np.uint64(31)) ^ rows[:, w]) * _M2
    return (h ^ (h >> np.uint64(29))) * _M3


def pieces(offsets: np.ndarray, ids: np.ndarray, edges: int = 1 << 20):
    """`ids` cut into consecutive runs of at most about `edges` CSR edges each, so a
    vectorised step over their edges needs bounded temporary memory (issue 12)."""
    if ids.size == 0:
        return
    cum = np.cumsum(offsets[ids + 1] - offsets[ids])
    if cum[-1] <= edges:
        yield ids
        return
    cuts = np.searchsorted(cum, np.arange(edges, int(cum[-1]), edges), side="right")
    yield from np.split(ids, np.unique(cuts))


def ranges(offsets: np.ndarray, ids: np.ndarray) -> np.ndarray:
    """Edge indices of the states `ids` (concatenated CSR rows)."""
    starts = offsets[ids]
    lens = offsets[ids + 1] - starts
    total = int(lens.sum())
    if total == 0:
        return np.zeros(0, np.int64)
    return np.arange(total, dtype=np.int64) + np.repeat(starts - (np.cumsum(lens) - lens), lens)


class StateStore:
    """Visited states, BFS parents and the edge list, for one search."""

    @staticmethod
    def row_bytes(total_bits: int) -> int:
        """Stored bytes per state: no padding to words (native.py's C knows it as KW)."""
        return max(1, -(-total_bits // 8))

    def __init__(self, total_bits: int, rules: int):
        self.words = max(1, -(-total_bits // 64))
        self.width = self.row_bytes(total_bits)
        self.keys = Grow(np.uint8, self.width, 1 << 12)
        self.parent = Grow(np.int32, 0, 1 << 12)
        self.degree = Grow(np.uint16, 0, 1 << 12)
        self.dst = Grow(np.int32, 0, 1 << 14)
        self.rule = Grow(np.uint8 if rules <= 256 else np.uint16, 0, 1 << 14)
        self.table: np.ndarray | None = np.full(1 << 12, -1, np.int32)
        self.offsets: np.ndarray | None = None
        self.rules = rules
        # (keys, empty table, its bits) -> table filled with ids 0..: set by the compiled search
        self.rehash: Callable[[np.ndarray, np.ndarray, int], None] | None = None

    def __len__(self) -> int:
        return self.keys.n

    # -- conversion ------------------------------------------------------------------
    def to_words(self, states: list[int]) -> np.ndarray:
        if self.words == 1:
            return np.fromiter(states, np.uint64, len(states)).reshape(-1, 1)
        size = 8 * self.words
        buf = b"".join(map(int.to_bytes, states, repeat(size), repeat("little")))
        return np.frombuffer(buf, "<u8").reshape(-1, self.words)

    def state(self, i: int) -> int:
        """The packed state with id `i`."""
        return int.from_bytes(self.keys.view[i].tobytes(), "little")

    def states(self, ids) -> list[int]:
        return [self.state(int(i)) for i in ids]

    def index_of(self, state: int) -> int:
        """Id of a stored state (a linear scan: for traces, not for the search)."""
        row = self.to_words([state])[0]
        hit = np.flatnonzero((self.keys.view == self._pack(row[None])[0]).all(axis=1))
        if not hit.size:
            raise KeyError(state)
        return int(hit[0])

    def _pack(self, rows: np.ndarray) -> np.ndarray:
        """uint64 word rows -> the stored rows of `width` bytes (little-endian, padding dropped)."""
        return rows.astype("<u8", copy=False).view(np.uint8).reshape(len(rows), 8 * self.words)[:, :self.width]

    def _unpack(self, rows: np.ndarray) -> np.ndarray:
        """Stored byte rows -> uint64 word rows, for hashing and bit-field arithmetic."""
        out = np.zeros((len(rows), 8 * self.words), np.uint8)
        out[:, :self.width] = rows
        return out.view("<u8").astype(np.uint64, copy=False)

    # -- hashing -------------------------------------------------------------------------
    def _hash(self, rows: np.ndarray) -> np.ndarray:
        return mix64(rows) >> np.uint64(64 - self.table_bits)

    @property
    def table_bits(self) -> int:
        return len(self.table).bit_length() - 1      # type: ignore[arg-type]

    def reserve(self, states: int, edges: int, expanded: int) -> None:
        """Room for `states` more states and `edges` more edges, degrees of states up to
        `expanded`, and a hash table that takes `states` more at its load limit (for a caller
        that writes into the arrays itself: the compiled search, model_check.native)."""
        for g in (self.keys, self.parent):
            g.reserve(states)
        for g in (self.dst, self.rule):
            g.reserve(edges)
        self.degree.reserve(expanded - self.degree.n)
        self._grow_table(len(self) + states)

    def _grow_table(self, need: int) -> None:
        size = len(self.table)                        # type: ignore[arg-type]
        if need <= LOAD * size:
            return
        while need > LOAD * size:
            size *= 2
        self.table = None                             # the old table goes before the new one comes
        _trim()
        keys = self.keys.view
        if self.rehash is not None:                   # the compiled search's: no temporaries at all, and it
            self.table = np.empty(size, np.int32)     # empties the slots itself (on the search's threads)
            self.rehash(keys, self.table, self.table_bits)
            return
        self.table = np.full(size, -1, np.int32)
        for lo in range(0, len(self), REHASH):        # in slices: the hash temporaries stay small
            rows = self._unpack(keys[lo:lo + REHASH])
            self._claim(self._hash(rows).astype(np.int64), np.arange(lo, lo + len(rows), dtype=np.int32),
                        lambda pending, ids: None)

    def _claim(self, slot: np.ndarray, values: np.ndarray, on_taken: Callable) -> np.ndarray:
        """Write `values` (distinct, >= 0 or marks <= -2) into free slots, probing in rounds.

        Every key still pending in round k has been probed k times, so all move by k: the
        triangular sequence, which visits every slot of a power-of-two table.

        `slot` is updated in place to where each value landed; `on_taken(pending, cur)`
        may return the positions among `pending` that are settled elsewhere (found equal)."""
        table, mask = self.table, len(self.table) - 1   # type: ignore[arg-type]
        pending = np.arange(len(values))
        settled = np.zeros(len(values), bool)
        step = 0
        while pending.size:
            step += 1
            sl = slot[pending]
            cur = table[sl]
            free = cur == -1
            busy = pending[~free]
            done = on_taken(busy, cur[~free])
            if done is not None:
                settled[busy[done]] = True
                busy = busy[~done]
            mine = pending[free]
            table[slot[mine]] = values[mine]
            won = table[slot[mine]] == values[mine]
            pending = np.concatenate((busy, mine[~won]))
            slot[pending] = (slot[pending] + step) & mask    # triangular probing: short chains
        return settled

    # -- building -----------------------------------------------------------------------------
    def add_initial(self, state: int) -> None:
        self._insert_new(self.to_words([state]), np.array([-1], np.int32))

    def _insert_new(self, rows: np.ndarray, parents: np.ndarray) -> None:
        first = len(self)
        self._grow_table(first + len(rows))
        ids = np.arange(first, first + len(rows), dtype=np.int32)
        self.keys.append(self._pack(rows))
        self.parent.append(parents)
        self._claim(self._hash(rows).astype(np.int64), ids, lambda pending, cur: None)

    def add_layer(self, lo: int, nxt: list[int], rules: list[int], ends: list[int]) -> list[int]:
        """Record the edges of the states lo .. lo+len(ends)-1 (see fastgen `edges`) and
        return the new states, in first-seen order (their ids follow the stored ones)."""
        # distinct successors of this layer in first-seen order (a dict keeps insertion order),
        # and for each edge the number of its successor among them
        distinct = list(dict.fromkeys(nxt))
        number = dict(zip(distinct, range(len(distinct))))
        inv = np.fromiter(map(number.__getitem__, nxt), np.int64, len(nxt))
        del number
        new = self.add_edges(lo, self.to_words(distinct) if distinct else None, inv, rules, ends)
        return [distinct[i] for i in new.tolist()]

    def add_edges(self, lo: int, distinct: np.ndarray | None, inv: np.ndarray, rules, ends) -> np.ndarray:
        """Record the edges of the states lo .. lo+len(ends)-1: `ends` (edges so far after each
        state), per edge its rule and `inv`, the index of its successor among `distinct` (uint64
        word rows, first-seen order). Returns the indices among `distinct` of the new states."""
        ends_a = np.asarray(ends, np.int64)
        if len(ends_a):
            deg = np.diff(ends_a, prepend=0)
            if deg.max() > 0xFFFF:     # pragma: no cover - a state with 65536 successors
                raise OverflowError("more than 65535 successors of one state")
            self.degree.append(deg.astype(np.uint16))
        if not len(inv):
            return np.zeros(0, np.int64)
        self.rule.append(np.asarray(rules, self.rule.data.dtype))
        ids, new = self._insert_distinct(distinct)
        # the parent of a new state is the source of the first edge reaching it; successors are
        # numbered in first-seen order, so a first occurrence is where the running maximum grows
        top = np.maximum.accumulate(inv)
        first = np.flatnonzero(np.concatenate(([True], top[1:] > top[:-1])))
        pos = first[new]
        self.parent.append((lo + np.searchsorted(ends_a, pos, side="right")).astype(np.int32))
        self.dst.append(ids[inv].astype(np.int32))
        return new

    def add_states(self, states: list[int]) -> list[int]:
        """As a bare visited set (the parallel search's workers): insert `states` and return the
        new ones in first-seen order; no parents, no edges."""
        distinct = list(dict.fromkeys(states))
        if not distinct:
            return []
        _, new = self._insert_distinct(self.to_words(distinct))
        return [distinct[i] for i in new.tolist()]

    def add_rows(self, rows: np.ndarray) -> np.ndarray:
        """`add_states` for uint64 word rows: the new ones (in sorted order, not first-seen)."""
        if not len(rows):
            return rows
        # distinct rows: sorted by their words (lexsort is a few times faster than unique(axis=0))
        reps = rows[np.lexsort(rows.T[::-1])]
        keep = np.ones(len(reps), bool)
        keep[1:] = (reps[1:] != reps[:-1]).any(axis=1)
        reps = reps[keep]
        _, new = self._insert_distinct(reps)
        return reps[new]

    def _insert_distinct(self, reps: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """For distinct rows `reps`: the id of each (stored or newly given) and which are new."""
        # probe the table: existing ids, or a mark (-2 - k) claiming a free slot for new key k
        self._grow_table(len(self) + len(reps))
        ids = np.full(len(reps), -1, np.int64)
        keys = self.keys.view
        packed = self._pack(reps)

        def seen(pending: np.ndarray, cur: np.ndarray) -> np.ndarray:
            eq = cur >= 0
            old, at = pending[eq], cur[eq]
            eq[eq] = (keys[at] == packed[old]).all(axis=1)
            ids[pending[eq]] = cur[eq]
            return eq

        slot = self._hash(reps).astype(np.int64)
        marks = (-2 - np.arange(len(reps))).astype(np.int32)
        new = np.flatnonzero(~self._claim(slot, marks, seen))     # ascending = first-seen order
        base = len(self)
        ids[new] = np.arange(base, base + len(new))
        self.table[slot[new]] = ids[new]                       # type: ignore[index]
        self.keys.append(packed[new])
        return ids, new

    def finish(self, keep_table: bool = False) -> None:
        """The search is over: drop the hash table (unless asked) and the degrees for CSR offsets,
        and give back the unused tail of every array (a shrinking mremap: no copy)."""
        if not keep_table:
            self.table = None
        for g in (self.keys, self.parent, self.dst, self.rule):
            g.trim()
        deg = self.degree.view
        self.offsets = np.zeros(len(deg) + 1, np.int32 if self.dst.n < 2 ** 31 else np.int64)
        np.cumsum(deg, out=self.offsets[1:])
        self.degree = Grow(np.uint16, 0, 1)

    @property
    def nbytes(self) -> int:
        arrays = [g.view for g in (self.keys, self.parent, self.degree, self.dst, self.rule)]
        return sum(a.nbytes for a in arrays + [a for a in (self.table, self.offsets) if a is not None])

    def coverage(self) -> list[int]:
        """Edges per rule. bincount widens its input to int64, 8 bytes per edge at once on the
        whole array (more than the stored graph's own bytes/state): counted in slices."""
        counts = np.zeros(self.rules, np.int64)
        rule = self.rule.view
        for lo in range(0, len(rule), COUNT):
            counts += np.bincount(rule[lo:lo + COUNT], minlength=self.rules)
        return counts.tolist()

    def path_to(self, i: int) -> list[int]:
        """Ids from the initial state to `i` along BFS parents (a shortest path)."""
        chain = [i]
        parent = self.parent.view
        while parent[chain[-1]] >= 0:
            chain.append(int(parent[chain[-1]]))
        return chain[::-1]

    # -- vectorised predicates -----------------------------------------------------------------
    def field(self, shift: int, width: int, lo: int, hi: int) -> np.ndarray:
        """The values of one bit field of states lo .. hi-1, as int64."""
        return _bits(self._unpack(self.keys.view[lo:hi]), shift, width)

    def mask(self, layout, defs: list[tuple[str, str]], text: str, chunk: int = 1 << 18) -> np.ndarray:
        """Boolean array: does the expression `text` hold in each stored state?"""
        out = np.empty(len(self), bool)
        for lo, hi, (val,) in self.evaluate(layout, defs, [text], chunk):
            out[lo:hi] = _truth(val) if np.ndim(val) else bool(val)
        return out

    def evaluate(self, layout, defs: list[tuple[str, str]], texts: list[str], chunk: int = 1 << 18):
        """(lo, hi, [value of each expression in states lo .. hi-1]) a chunk of states at a time;
        a value is an array, or a plain number where the expression is constant."""
        nodes = [expr.parse(t) for t in texts]
        define = {name: expr.parse(t) for name, t in defs}
        for lo in range(0, len(self), chunk):
            hi = min(lo + chunk, len(self))
            cache: dict[str, np.ndarray] = {}
            words = self._unpack(self.keys.view[lo:hi])

            def name(n: str) -> np.ndarray:
                if n not in cache:
                    cache[n] = (_eval(define[n], name) if n in define
                                else _bits(words, layout.shift[n], layout.width[n]))
                return cache[n]
            yield lo, hi, [_eval(node, name) for node in nodes]
            # `name` refers to itself (a cycle the gc frees late): free what it holds now
            cache.clear()
            words = None


def _bits(words: np.ndarray, shift: int, width: int) -> np.ndarray:
    """One bit field of uint64 word rows, as int64."""
    word, off = divmod(shift, 64)
    v = words[:, word] >> np.uint64(off)
    if off + width > 64:
        v = v | (words[:, word + 1] << np.uint64(64 - off))
    return (v & np.uint64((1 << width) - 1)).astype(np.int64)


def _truth(v):
    return v if getattr(v, "dtype", None) == bool else v != 0


def _eval(node: ast.expr, name: Callable[[str], np.ndarray]):
    """The shared expression language (model_check.expr) over numpy arrays."""
    def e(n):
        return _eval(n, name)

    if isinstance(node, ast.Name):
        return name(node.id)
    if isinstance(node, ast.Constant):
        return node.value if isinstance(node.value, bool) else int(node.value)
    if isinstance(node, ast.BoolOp):
        vals = [_truth(e(v)) for v in node.values]
        out = vals[0]
        for v in vals[1:]:
            out = (out & v) if isinstance(node.op, ast.And) else (out | v)
        return out
    if isinstance(node, ast.UnaryOp):
        val = e(node.operand)
        return np.logical_not(_truth(val)) if isinstance(node.op, ast.Not) else -_num(val)
    if isinstance(node, ast.BinOp):
        a, b = _num(e(node.left)), _num(e(node.right))
        op = type(node.op)
        return {ast.Add: np.add, ast.Sub: np.subtract, ast.Mult: np.multiply,
                ast.FloorDiv: np.floor_divide, ast.Mod: np.mod}[op](a, b)
    if isinstance(node, ast.Compare):
        a, b = _num(e(node.left)), _num(e(node.comparators[0]))
        op = type(node.ops[0])
        return {ast.Eq: np.equal, ast.NotEq: np.not_equal, ast.Lt: np.less, ast.LtE: np.less_equal,
                ast.Gt: np.greater, ast.GtE: np.greater_equal}[op](a, b)
    if isinstance(node, ast.IfExp):
        return np.where(_truth(e(node.test)), _num(e(node.body)), _num(e(node.orelse)))
    if isinstance(node, ast.Call):
        a, b = (_num(e(x)) for x in node.args)
        return (np.minimum if node.func.id == "min" else np.maximum)(a, b)   # type: ignore[attr-defined]
    raise expr.ExprError(f"cannot evaluate {ast.dump(node)[:40]}")


def _num(v):
    return v.astype(np.int64) if getattr(v, "dtype", None) == bool else (int(v) if isinstance(v, bool) else v)
