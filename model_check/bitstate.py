"""Bitstate ("supertrace") and hash-compact search for state spaces that do not fit in memory (issue 12, item 5).

Like SPIN's -DBITSTATE: the visited set is an array of m = 2**bits bits and a state counts
as visited when all k of its bit positions are set (k = 3, SPIN's default -k3). Nothing
else is stored per state, so memory is m/8 bytes whatever the model's size; the price is
that a new state whose k bits happen to be set already is taken for visited and skipped,
together with whatever only it leads to. A pass is therefore NOT a proof.

The expected loss is printed from the standard Bloom-filter analysis of bitstate hashing
(Holzmann, "An analysis of bitstate hashing", 1998; SPIN reports the hash factor m/n):
after i states are stored, a new state is wrongly taken for visited with probability
p_i = (1 - e^(-k i / m))^k; over a search that stored n states the expected number of
such omissions is sum(p_i), the expected coverage n / (n + sum(p_i)), and the chance that
nothing at all was missed exp(-sum(p_i)).

Hash-compact (SPIN's -DHC): the visited set holds a b-bit signature of each state (8 bytes a state in a
sorted array) instead of the state; two states with one signature are taken for one, so about
n (n - 1) / 2^(b+1) states are omitted (the birthday bound), far fewer than bitstate at the same memory
for spaces of up to some hundred million states. A pass is NOT a proof here either.

Safety only (invariants, deadlocks, rule coverage): no graph is kept, so there are no
response bounds or liveness verdicts and a violation is reported with its state only.
The search is breadth-first over the same generated `edges` function as the exhaustive
one; within a layer the distinct successors are tested against the bits set before that
layer and then inserted together (so duplicates within a layer are never lost).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from model_check.compile import Compiled, compile_model
from model_check.engine import Progress, Result
from model_check.gcl import Model
from model_check.storage import Meter, StateStore, mix64
from model_check.trace import Step, Violation

HASHES = 3                        # bit positions per state (SPIN's default -k3)
_ODD = np.uint64(0x2545F4914F6CDD1D)


class _Omissions:
    """What both estimates derive from the expected number of states omitted."""

    states: int
    expected_omitted: float

    @property
    def coverage(self) -> float:
        return self.states / (self.states + self.expected_omitted) if self.states else 1.0

    @property
    def none_missed(self) -> float:
        return math.exp(-self.expected_omitted)


@dataclass
class Estimate(_Omissions):
    """The printed coverage estimate of one bitstate run."""

    bits: int                     # log2 of the number of bits m
    hashes: int                   # k
    states: int                   # n, states stored
    expected_omitted: float       # sum of p_i over the n insertions
    last_p: float                 # p_n: chance the next new state would be lost

    @property
    def hash_factor(self) -> float:
        return (1 << self.bits) / max(self.states, 1)


    def text(self) -> str:
        return (f"BITSTATE search: 2^{self.bits} bits ({(1 << self.bits) / 8 / 2 ** 20:.1f} MB), k = {self.hashes} "
                f"hash functions, hash factor m/n = {self.hash_factor:,.1f}; expected states omitted "
                f"{self.expected_omitted:,.1f} (coverage ~ {100 * self.coverage:.3f} %), probability that no "
                f"state was omitted {100 * self.none_missed:.2f} %. States reachable only through an omitted one "
                f"are lost as well, so on deep, narrow state graphs the coverage is lower than this. "
                f"A pass in this mode is NOT a proof.")


def expected_omissions(n: int, m: int, k: int) -> tuple[float, float]:
    """(sum of p_i for i < n, p_n) with p_i = (1 - e^(-k i/m))^k, summed in closed chunks."""
    if n <= 0:
        return 0.0, 0.0
    i = np.arange(n, dtype=np.float64)
    p = (-np.expm1(-k * i / m)) ** k
    return float(p.sum()), float((-math.expm1(-k * n / m)) ** k)


def positions(rows: np.ndarray, bits: int, k: int) -> np.ndarray:
    """k bit positions per state (rows of uint64 words): double hashing h1 + j*h2 of two
    independent 64-bit mixes (Kirsch and Mitzenmacher), each reduced to `bits` bits."""
    h1 = mix64(rows)
    h2 = mix64(rows, _ODD) | np.uint64(1)
    shift = np.uint64(64 - bits)
    return np.stack([(h1 + np.uint64(j) * h2) >> shift for j in range(k)])


class _Bits:
    """The bitstate visited set: 2**bits bits, k positions per state."""

    def __init__(self, bits: int, hashes: int) -> None:
        self.bits, self.hashes = bits, hashes
        self.table = np.zeros(1 << (bits - 3), np.uint8)

    def add_new(self, rows: np.ndarray) -> np.ndarray:
        """Mark the states (uint64 word rows) visited; True where one was not (apparently) visited before."""
        pos = positions(rows, self.bits, self.hashes)
        new = ~_all_set(self.table, pos)
        _insert(self.table, pos[:, new])
        return new

    @property
    def nbytes(self) -> int:
        return self.table.nbytes


class _Compact:
    """The hash-compact visited set (SPIN's -DHC): a sorted array of `bits`-bit signatures of the states."""

    def __init__(self, bits: int) -> None:
        self.bits = bits
        self.seen = np.zeros(0, np.uint64)

    def add_new(self, rows: np.ndarray) -> np.ndarray:
        sig = mix64(rows) >> np.uint64(64 - self.bits)
        sig_unique, first = np.unique(sig, return_index=True)      # two states of one layer with one signature:
        new = np.zeros(len(sig), bool)                            # the later is taken for the first (an omission)
        fresh = ~np.isin(sig_unique, self.seen, assume_unique=True)
        new[first[fresh]] = True
        self.seen = np.union1d(self.seen, sig_unique[fresh])
        return new

    @property
    def nbytes(self) -> int:
        return self.seen.nbytes


def explore_bitstate(model: Model, bits: int, compiled: Compiled | None = None, progress: bool = True,
                     hashes: int = HASHES) -> tuple[Result, Estimate]:
    """Breadth-first safety search with a 2**bits-bit visited set; see the module docstring."""
    res = _explore(model, _Bits(bits, hashes), compiled, progress)
    omitted, last = expected_omissions(res.states, 1 << bits, hashes)
    est = Estimate(bits, hashes, res.states, omitted, last)
    res.warnings.append(est.text())
    return res, est


def explore_hash_compact(model: Model, bits: int, compiled: Compiled | None = None,
                         progress: bool = True) -> tuple[Result, "CompactEstimate"]:
    """Breadth-first safety search that stores a `bits`-bit signature per state (SPIN's hash-compact, -DHC)
    instead of the state: 8 bytes a state whatever the model. Two states with one signature are taken for
    one, so a pass is NOT a proof either; the estimate says how likely that was."""
    res = _explore(model, _Compact(bits), compiled, progress)
    est = CompactEstimate(bits, res.states)
    res.warnings.append(est.text())
    return res, est


@dataclass
class CompactEstimate(_Omissions):
    """The printed estimate of one hash-compact run: with n signatures of b bits drawn at random, new state i
    meets one of the i stored signatures with probability i / 2^b (the birthday bound), so about
    n (n - 1) / 2^(b + 1) states are omitted, and none at all with probability e^(-that)."""

    bits: int
    states: int

    @property
    def expected_omitted(self) -> float:
        return self.states * (self.states - 1) / 2 ** (self.bits + 1)


    def text(self) -> str:
        return (f"HASH-COMPACT search: {self.bits}-bit signatures, {self.states:,} stored ({8 * self.states / 2 ** 20:.1f} MB);"
                f" expected states omitted {self.expected_omitted:,.3g} (coverage ~ {100 * self.coverage:.4f} %), "
                f"probability that no state was omitted {100 * self.none_missed:.2f} %. States reachable only "
                f"through an omitted one are lost as well, so on deep, narrow state graphs the coverage is lower "
                f"than this. A pass in this mode is NOT a proof.")


def _explore(model: Model, visited: "_Bits | _Compact", compiled: Compiled | None, progress: bool) -> Result:
    comp = compiled or compile_model(model)
    res = Result(model=model, compiled=comp, coverage=[0] * len(model.rules), proof=False)
    if model.responses:
        res.warnings.append("this mode checks safety only: the response properties were not checked")
    meter = Meter()
    bar = Progress(model.name) if progress else None
    t0, c0 = time.perf_counter(), time.process_time()
    words = StateStore(comp.layout.total_bits, len(model.rules))     # for its to_words only
    cov = np.zeros(len(model.rules), np.int64)
    visited.add_new(words.to_words([comp.init]))
    frontier, states, transitions, depth, hit = [comp.init], 1, 0, 0, None
    while frontier:
        nxt: list[int] = []
        rules: list[int] = []
        ends: list[int] = []
        hit = comp.edges(frontier, nxt, rules, ends)
        transitions += len(nxt)
        if rules:
            cov += np.bincount(np.asarray(rules, np.int64), minlength=len(model.rules))
        if hit is not None:
            break
        distinct = list(dict.fromkeys(nxt))
        new = visited.add_new(words.to_words(distinct)) if distinct else np.zeros(0, bool)
        frontier = [distinct[i] for i in np.flatnonzero(new).tolist()]
        states += len(frontier)
        if frontier:
            depth += 1
        if bar:
            bar.update(depth, states, len(frontier))
    res.seconds = time.perf_counter() - t0
    res.times["search"] = time.process_time() - c0
    res.states, res.transitions, res.depth = states, transitions, depth
    res.coverage = cov.tolist()
    if hit is not None:
        kind, index, state = hit
        prop = model.invariants[index].name if kind == "invariant" else "no deadlock"
        res.violation = Violation(kind, prop, [Step(None, state)],
                                  detail="this mode keeps no parents: the state is shown without its "
                                         "trace (run without --bitstate / --hash-compact for a shortest one)")
    res.store_bytes = visited.nbytes
    res.peak_bytes = meter.peak()
    res.cpu = time.process_time() - c0
    return res


def _all_set(table: np.ndarray, pos: np.ndarray) -> np.ndarray:
    ok = np.ones(pos.shape[1], bool)
    for row in pos:
        ok &= (table[row >> np.uint64(3)] >> (row & np.uint64(7)).astype(np.uint8)) & np.uint8(1) == 1
    return ok


def _insert(table: np.ndarray, pos: np.ndarray) -> None:
    for row in pos:
        np.bitwise_or.at(table, row >> np.uint64(3), np.left_shift(np.uint8(1), (row & np.uint64(7)).astype(np.uint8)))
