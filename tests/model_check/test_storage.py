"""The compact state store against plain Python sets, dicts and the compiled predicates."""
import mmap
import random

import numpy as np

import pytest

from model_check import spec_adapter as sa
from model_check.compile import compile_model
from model_check.engine import explore
from model_check.models import id_retry
from model_check.storage import COUNT, Grow, Meter, StateStore


@pytest.mark.parametrize("bits", [20, 64, 129, 200])
def test_layers_deduplicate_like_a_set_and_keep_first_seen_order(bits):
    """Random successor lists with many repeats, over several table growths."""
    rng = random.Random(bits)
    pool = [rng.getrandbits(bits) for _ in range(3000)]
    store = StateStore(bits, 5)
    store.add_initial(pool[0])
    seen, order = {pool[0]}, [pool[0]]
    lo, frontier, edges = 0, [pool[0]], []
    while frontier:
        nxt, rules, ends = [], [], []
        for _ in frontier:
            for _ in range(rng.randint(0, 4)):
                nxt.append(rng.choice(pool))
                rules.append(rng.randrange(5))
            ends.append(len(nxt))
        edges += nxt
        want = [s for s in dict.fromkeys(nxt) if s not in seen]
        new = store.add_layer(lo, nxt, rules, ends)
        assert new == want
        seen.update(new)
        order += new
        lo += len(frontier)
        frontier = new
    store.finish()
    assert len(store) == len(seen)
    assert store.states(range(len(store))) == order
    # every edge points at the id of its successor; parents are the first source reaching it
    index = {s: i for i, s in enumerate(order)}
    assert all(store.parent.view[i] < i for i in range(1, len(store)))
    assert store.index_of(order[-1]) == len(order) - 1
    assert store.dst.view.tolist() == [index[s] for s in edges]


def test_vectorised_predicates_equal_the_compiled_ones():
    spec = sa.load()
    model = id_retry.build(sa.identification(spec, "first"), 2)
    res = explore(model, progress=False)
    comp, store = res.compiled, res.store
    states = store.states(range(len(store)))
    for key, text in [("final", model.final)] + [(f"inv{i}", inv.expr) for i, inv in enumerate(model.invariants)] \
            + [(f"trigger{i}", r.trigger) for i, r in enumerate(model.responses)]:
        mask = store.mask(comp.layout, model.defs, text, chunk=97)
        assert mask.tolist() == [comp.predicates[key](s) for s in states], key


def test_edges_and_coverage_match_the_compiled_successors():
    spec = sa.load()
    model = id_retry.build(sa.identification(spec, "sensor"), 2)
    comp = compile_model(model)
    res = explore(model, comp, progress=False)
    store = res.store
    for i in range(0, len(store), 7):
        s = store.state(i)
        lo, hi = int(store.offsets[i]), int(store.offsets[i + 1])
        got = list(zip(store.rule.view[lo:hi].tolist(), store.states(store.dst.view[lo:hi])))
        assert got == [(r, comp.canon(ns)) for r, ns in comp.successors(s)]
    assert res.bytes_per_state >= 0 and set(res.times) - {"compile"} == {"search", "bounds", "liveness"}


def test_coverage_counted_in_slices_is_the_whole_count():
    """`coverage` counts the rules of the edges a slice of COUNT at a time (bincount widens its
    input to int64): the sum over the slices, the last one partial, is the whole array's count."""
    rng = np.random.default_rng(3)
    store = StateStore(20, 300)                   # more than 256 rules: uint16 rule numbers
    rules = rng.integers(0, 300, 2 * COUNT + 17).astype(store.rule.data.dtype)
    store.rule.append(rules)
    assert store.coverage() == np.bincount(rules.astype(np.int64), minlength=300).tolist()


def test_meter_counts_anonymous_memory_not_file_pages(tmp_path):
    """The peak counts the arrays a check fills; the file-backed pages it faults in (here a
    mapped file, in a check the code of numpy's loops and of the model's shared object) are code
    or page cache, not the check's data (issue 12 item 3: 150 of 208 bytes/state on 1,816 states)."""
    size = 8 << 20
    path = tmp_path / "pages"
    path.write_bytes(bytes(size))
    meter = Meter()
    with path.open("rb") as fh, mmap.mmap(fh.fileno(), 0, access=mmap.ACCESS_READ) as mapped:
        assert sum(mapped[i] for i in range(0, size, 4096)) == 0     # every page resident
        assert meter.peak() < size // 4
        data = np.ones(size, np.uint8)               # 8 MB of anonymous, written memory
        assert meter.peak() >= size * 0.9
        del data


def test_slicing_wide_layers_changes_nothing(monkeypatch):
    """The engine expands a wide layer in slices; ids, parents, edges and verdicts stay the same."""
    from model_check import engine
    from tests.model_check import toys
    spec = sa.load()
    for model in (id_retry.build(sa.identification(spec, "sensor"), 2), toys.mutex(3, lock=False)):
        whole = explore(model, progress=False)
        monkeypatch.setattr(engine, "SLICE", 3)
        sliced = explore(model, progress=False)
        monkeypatch.undo()
        assert (sliced.states, sliced.transitions, sliced.depth, sliced.coverage, sliced.bounds) == \
            (whole.states, whole.transitions, whole.depth, whole.coverage, whole.bounds)
        assert sliced.store.parent.view.tolist() == whole.store.parent.view.tolist()
        assert sliced.store.dst.view.tolist() == whole.store.dst.view.tolist()
        assert (sliced.violation is None) == (whole.violation is None)
        if whole.violation:
            assert [s.state for s in sliced.violation.trace] == [s.state for s in whole.violation.trace]


def test_grown_arrays_keep_their_rows_and_read_zero_beyond():
    """Grow starts as a heap block and crosses into its own mapping (mremap, no zero-fill by
    numpy) from 1 MiB: the rows written stay through growth, the crossing and trim, capacity never written reads 0 (the kernel's pages, not garbage),
    and a view taken before the Grow is dropped still holds its memory."""
    g = Grow(np.uint8, 3, 2)
    rows = np.arange(3 * 5000, dtype=np.uint32).astype(np.uint8).reshape(-1, 3)
    for lo in range(0, len(rows), 700):
        g.append(rows[lo:lo + 700])
    g.reserve(1 << 21)                                          # 6 MiB: a move and the huge-page hint
    assert len(g.data) >= g.n + (1 << 21) and np.array_equal(g.view, rows)
    assert not g.data[g.n:].any()
    g.trim()
    assert len(g.data) == g.n and np.array_equal(g.view, rows)
    kept = g.view
    del g
    assert np.array_equal(kept, rows)
