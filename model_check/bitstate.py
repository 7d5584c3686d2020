"""Bitstate ("supertrace") search for state spaces that do not fit in memory (issue 12, item 5).

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


@dataclass
class Estimate:
    """The printed coverage estimate of one bitstate run."""

    bits: int                     # log2 of the number of bits m
    hashes: int                   # k
    states: int                   # n, states stored
    expected_omitted: float       # sum of p_i over the n insertions
    last_p: float                 # p_n: chance the next new state would be lost

    @property
    def hash_factor(self) -> float:
        return (1 << self.bits) / max(self.states, 1)

    @property
    def coverage(self) -> float:
        return self.states / (self.states + self.expected_omitted) if self.states else 1.0

    @property
    def none_missed(self) -> float:
        return math.exp(-self.expected_omitted)

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


def explore_bitstate(model: Model, bits: int, compiled: Compiled | None = None, progress: bool = True,
                     hashes: int = HASHES) -> tuple[Result, Estimate]:
    """Breadth-first safety search with a 2**bits-bit visited set; see the module docstring."""
    comp = compiled or compile_model(model)
    res = Result(model=model, compiled=comp, coverage=[0] * len(model.rules), proof=False)
    if model.responses:
        res.warnings.append("bitstate mode checks safety only: the response properties were not checked")
    meter = Meter()
    bar = Progress(model.name) if progress else None
    t0, c0 = time.perf_counter(), time.process_time()
    table = np.zeros(1 << (bits - 3), np.uint8)
    words = StateStore(comp.layout.total_bits, len(model.rules))     # for its to_words only
    cov = np.zeros(len(model.rules), np.int64)
    _insert(table, positions(words.to_words([comp.init]), bits, hashes))
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
        pos = positions(words.to_words(distinct), bits, hashes) if distinct else np.zeros((hashes, 0), np.uint64)
        new = ~_all_set(table, pos)
        _insert(table, pos[:, new])
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
                                  detail="bitstate mode keeps no parents: the state is shown without its "
                                         "trace (run without --bitstate for a shortest one)")
    omitted, last = expected_omissions(states, 1 << bits, hashes)
    est = Estimate(bits, hashes, states, omitted, last)
    res.warnings.append(est.text())
    res.store_bytes = table.nbytes
    res.peak_bytes = meter.peak()
    res.cpu = time.process_time() - c0
    return res, est


def _all_set(table: np.ndarray, pos: np.ndarray) -> np.ndarray:
    ok = np.ones(pos.shape[1], bool)
    for row in pos:
        ok &= (table[row >> np.uint64(3)] >> (row & np.uint64(7)).astype(np.uint8)) & np.uint8(1) == 1
    return ok


def _insert(table: np.ndarray, pos: np.ndarray) -> None:
    for row in pos:
        np.bitwise_or.at(table, row >> np.uint64(3), np.left_shift(np.uint8(1), (row & np.uint64(7)).astype(np.uint8)))
