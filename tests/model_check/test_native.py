"""The C successor function (model_check.native) against the Python reference generator.

It must give the very same search: successors in rule order, first-seen ids,
parents, edges, coverage, hits and counterexamples, wherever in a search it
takes over and however often a call stops on full buffers. Small models, with
the switch-over threshold at 0 so that they run on it.
"""
import random

import numpy as np
import pytest

from model_check import engine, native
from model_check import spec_adapter as sa
from model_check.compile import RangeError, compile_model
from model_check.engine import explore
from model_check.gcl import Model, Rule, SymGroup, Var
from model_check.models import post
from model_check.storage import StateStore
from tests.model_check import toys
from tests.model_check.test_fastgen import MODELS, _reference_step, _same

def _wide() -> Model:
    """Fields of 30 bits, one across the first 64-bit word boundary, in a symmetry group: states of
    several words, as id_retry's 129 bits and POST's 80 are."""
    vs = [Var(f"c{i}", (1 << 30) - 1) for i in range(3)] + [Var("t", 3)]
    rules = [Rule(f"up{i}", f"c{i} < 3 and t < 3", ((f"c{i}", f"c{i} + 1 + t"), ("t", "t + 1"))) for i in range(3)]
    rules.append(Rule("big", "t == 3 and c0 < 5", (("c0", "c0 * 100000000 + 7"), ("t", "0"))))
    return Model("wide", vs, rules, final="True",
                 symmetry=[SymGroup("counters", tuple((f"c{i}",) for i in range(1, 3)))])


SMALL = [m for m in MODELS if m[0] in ("mutex-broken", "dining", "countdown", "tokens-sym", "sequential",
                                       "arb-seed-2", "arb-colliders-2")] + [("wide", lambda s: _wide())]


@pytest.mark.parametrize("build", [b for _, b in MODELS] + [lambda s: _wide()], ids=[n for n, _ in MODELS] + ["wide"])
def test_native_successors_of_random_states_equal_reference(spec, build):
    """Arbitrary in-range states, reachable or not: hit, successors in order, rule counts."""
    model = build(spec)
    comp = compile_model(model)
    nat = comp.native()
    assert nat is not None, "no C compiler, or the model is not translated"
    rng = random.Random(3)
    for _ in range(300):
        s = comp.layout.pack({v.name: rng.randint(0, v.hi) for v in model.vars})
        chunk = nat.expand(StateStore(comp.layout.total_bits, 1).to_words([s]))
        try:
            want_hit, want, counts = _reference_step(comp, model, s)
        except RangeError as exc:
            assert chunk.kind == native.HIT_RANGE
            assert str(exc).split(" = ")[0] == f"{model.rules[chunk.rule].name}: {model.vars[chunk.var].name}"
            continue
        if want_hit is not None:
            assert (chunk.kind, chunk.done) == ({"invariant": native.HIT_INVARIANT,
                                                 "deadlock": native.HIT_DEADLOCK}[want_hit[0]], 0)
            assert want_hit[0] == "deadlock" or chunk.index == want_hit[1]
            continue
        got = [int.from_bytes(r.astype("<u8").tobytes(), "little") for r in chunk.distinct]
        assert (chunk.kind, chunk.done, got) == (native.HIT_NONE, 1, want), hex(s)
        assert np.bincount(chunk.rules, minlength=len(model.rules)).tolist() == counts


@pytest.mark.parametrize("after", [0, 5])
@pytest.mark.parametrize("build", [b for _, b in SMALL], ids=[n for n, _ in SMALL])
def test_native_search_equals_reference(spec, build, after, monkeypatch):
    """From the first state (0) or mid-search (5), with calls stopped by tiny buffers."""
    model = build(spec)
    ref = explore(model, compile_model(model, optimise=False), progress=False)
    monkeypatch.setattr(engine, "NATIVE_AFTER", after)
    monkeypatch.setattr(native, "MAX_EDGES", 7)
    comp = compile_model(model)
    got = explore(model, comp, progress=False)
    assert comp.native() is not None and "compile" in got.times
    _same(got, ref)
    assert got.store.parent.view.tolist() == ref.store.parent.view.tolist()
    assert got.store.dst.view.tolist() == ref.store.dst.view.tolist()
    assert got.store.rule.view.tolist() == ref.store.rule.view.tolist()


def test_native_out_of_range_effect_is_the_same_error(monkeypatch):
    m = Model("bad", [Var("x", 2), Var("y", 3)], [Rule("inc", "True", (("y", "y + 1"), ("x", "x + y")))])
    with pytest.raises(RangeError) as python:
        explore(m, progress=False)
    monkeypatch.setattr(engine, "NATIVE_AFTER", 0)
    with pytest.raises(RangeError) as c:
        explore(m, progress=False)
    assert str(c.value) == str(python.value) == "inc: x = 3"


def test_without_a_compiler_the_python_path_runs(monkeypatch):
    monkeypatch.setenv("ARACHNAE_NATIVE", "0")
    monkeypatch.setattr(engine, "NATIVE_AFTER", 0)
    comp = compile_model(toys.mutex(3))
    res = explore(toys.mutex(3), comp, progress=False)
    assert comp.native() is None and res.ok and res.states == explore(toys.mutex(3), progress=False).states


def test_post_oracle_screen_equals_the_oracle(spec):
    """The bulk oracle the engine screens final states with flags exactly what the scalar one reports."""
    p = sa.post(spec)
    t = post.Tree(p, None)
    names = {t.var[s]: s for s in t.var}
    rng = random.Random(7)
    views = []
    for _ in range(400):
        pr = rng.choice([0.5, 0.9, 0.97])
        views.append({"mcp": rng.choice([1, 1, 1, 2]), "vd": rng.randint(1, 3),
                      **{x: int(rng.random() < pr) for x in names}})
    bulk = post.oracle_screen(p, t, names, {k: np.array([v[k] for v in views]) for k in views[0]})
    assert bulk.tolist() == [post.oracle_mismatch(p, t, names, v) is not None for v in views]
    assert 0 < bulk.sum() < len(views)
