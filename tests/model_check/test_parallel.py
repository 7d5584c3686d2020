"""The parallel search (issue 12, item 4) against the sequential one: the same store (ids,
parents, edges), so the same counts, layers, bounds, verdicts and counterexamples."""
import json

import numpy as np
import pytest

from model_check import native, parallel
from model_check import spec_adapter as sa
from model_check.checks import build_models
from model_check.compile import RangeError, compile_model
from model_check.engine import explore
from model_check.gcl import Invariant, Rule
from tests.model_check import toys


def _wide_failures():
    """Violations deep inside wide layers, so the state that fails is in a later slice."""
    inv = toys.torus(3, 12)
    inv.name, inv.invariants = "torus_invariant", [Invariant("not_there", "not (c0 == 5 and c1 == 4 and c2 == 6)")]
    yield inv
    dead = toys.torus(3, 12)
    dead.name, dead.final = "torus_deadlock", "False"
    dead.rules = [Rule(r.name, f"({r.guard}) and not (c0 == 6 and c1 == 5 and c2 == 3)", r.effect)
                  for r in dead.rules]
    yield dead


def _models(workers: int):
    spec = sa.load()
    yield from build_models("id_retry", spec, size=3)                    # both buses; responses with bounds
    yield from build_models("arbitration", spec, bus="sensor", size=3)
    yield from build_models("arbitration", spec, variant="seed", bus="first", size=2)
    if workers == 2:                                                     # 74,312 states: once is enough
        yield from build_models("post", spec, legs=1)                    # symmetry reduction, final checks
    yield from build_models("reaction", spec, size=1)
    yield toys.tokens(4, 3)
    yield toys.countdown(5, stutter=True)                                # a fair-only response
    yield toys.mutex(3, lock=False)                                      # invariant violated
    yield toys.dining(3)                                                 # deadlock
    yield from _wide_failures()


@pytest.fixture
def rounds(monkeypatch):
    """Small rounds, every slice busy, buffers that fill (later slices expanded in vain), and a
    return to Python after every round."""
    monkeypatch.setattr(parallel, "NARROW", 0)
    monkeypatch.setattr(parallel, "EDGES", 96)
    monkeypatch.setattr(parallel, "ROUNDS", 1)


def _store(res):
    st = res.store
    return [st.keys.view, st.parent.view, st.dst.view, st.rule.view, st.offsets]


@pytest.mark.parametrize("workers", [2, 3])
def test_parallel_equals_sequential(workers, rounds):
    for model in _models(workers):
        seq = explore(model, progress=False, use_native=True)
        par = explore(model, progress=False, use_native=True, workers=workers)
        name = model.name
        assert par.native is not None and par.rounds.rounds > 0, name     # the threaded search ran
        assert (par.ok, par.states, par.transitions, par.depth, par.coverage, par.layer_starts, par.bounds) == \
            (seq.ok, seq.states, seq.transitions, seq.depth, seq.coverage, seq.layer_starts, seq.bounds), name
        assert all(np.array_equal(a, b) for a, b in zip(_store(par), _store(seq))), name
        assert par.warnings == seq.warnings, name
        if not seq.ok:
            v, w = par.violation, seq.violation
            assert (v.kind, v.prop, v.detail) == (w.kind, w.prop, w.detail), name
            assert [s.state for s in v.trace] == [s.state for s in w.trace], name


def test_the_slices_share_the_work_and_refill(rounds):
    """The rounds really split the states across the threads, and a slice that filled its
    buffers drops the slices after it (they are expanded again in the next round)."""
    (model,) = build_models("id_retry", sa.load(), bus="sensor", size=3)
    seq = explore(model, progress=False, use_native=True)
    par = explore(model, progress=False, use_native=True, workers=3)
    assert par.states == seq.states and np.array_equal(_store(par)[2], _store(seq)[2])
    r = par.rounds
    assert r.split > r.rounds // 2 and 0 < r.dropped < r.rounds, r


def test_a_range_error_in_a_later_slice_is_the_sequential_one(rounds):
    model = toys.torus(3, 12)
    model.rules = model.rules + [Rule("boom", "c0 == 3 and c1 == 7 and c2 == 2", (("c2", "c2 + 20"),))]
    with pytest.raises(RangeError) as seq:
        explore(model, progress=False, use_native=True)
    with pytest.raises(RangeError) as par:
        explore(model, progress=False, use_native=True, workers=2)
    assert str(par.value) == str(seq.value) and "boom" in str(seq.value)


def test_cli_runs_the_parallel_search(capsys):
    """`--workers 2` checks every property, with the figures of one thread."""
    from arachnae.cli import main
    args = ["check", "id_retry", "--bus", "sensor", "--size", "3", "--quiet", "--json"]
    assert main(args) == 0
    one = json.loads(capsys.readouterr().out)[0]
    assert main(args + ["--workers", "2"]) == 0
    two = json.loads(capsys.readouterr().out)[0]
    keep = ("holds", "states", "transitions", "depth", "invariants", "responses", "bound_ticks", "never_fired",
            "warnings")
    assert one["holds"] and one["responses"] and {k: one[k] for k in keep} == {k: two[k] for k in keep}
    assert main(["check", "id_retry", "--workers", "2", "--bitstate", "20"]) == 1
    assert "choose one" in capsys.readouterr().err


def test_extra_compiler_flags_build_their_own_library(monkeypatch, rounds):
    """ARACHNAE_NATIVE_CFLAGS (here the phase timers, -DPSTAT) is part of the cache key, and the
    timed build still compiles and runs the threaded search to the same store: a build that
    fails to compile would leave the search on the Python path without a word."""
    model = toys.tokens(4, 3)
    plain = compile_model(model).native.lib()
    monkeypatch.setenv(native.EXTRA_FLAGS_ENV, "-DPSTAT")
    comp = compile_model(model)
    assert comp.native.lib() != plain
    seq = explore(model, progress=False, use_native=True)
    par = explore(model, comp, progress=False, use_native=True, workers=2)
    assert par.native is not None and par.rounds.rounds > 0
    assert all(np.array_equal(a, b) for a, b in zip(_store(par), _store(seq)))


def test_a_grown_table_is_emptied_by_its_rehash(monkeypatch, rounds):
    """The compiled search's grown table comes unset (np.empty): its rehash empties every slot
    itself (on all the threads in the threaded search). Filled with a stored id first (what a
    slot it missed would hold), the table still gives the one store."""
    model = toys.torus(3, 20)                                  # 8,000 states: the table grows twice
    ref = explore(model, progress=False, use_native=True)
    calls = []

    def dirty(fn):
        def rehash(*a):
            table = a[-2]
            table[:] = 0
            calls.append(len(table))
            fn(*a)
        return rehash
    monkeypatch.setattr(native.Native, "rehash", dirty(native.Native.rehash))
    monkeypatch.setattr(parallel, "_rehash", dirty(parallel._rehash))
    for workers in (1, 2):
        got = explore(model, progress=False, use_native=True, workers=workers)
        assert got.states == ref.states and all(np.array_equal(a, b) for a, b in zip(_store(got), _store(ref)))
    assert len(calls) >= 2 and max(calls) >= 1 << 14, calls
