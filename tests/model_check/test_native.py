"""The C successor function (model_check.native) against the Python reference generator.

It must give the very same search: successors in rule order, first-seen ids,
parents, edges, coverage, hits and counterexamples, wherever in a search it
takes over and however often a call stops on full buffers. Small models, with
the switch-over threshold at 0 so that they run on it.
"""
import random

import numpy as np
import pytest

from model_check import engine, liveness, native, storage
from model_check import spec_adapter as sa
from model_check.compile import RangeError, compile_model
from model_check.engine import explore
from model_check.gcl import Model, Response, Rule, SymGroup, Var
from model_check.models import arbitration, id_retry, post
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
    """From the first state (0) or mid-search (5), with calls stopped by full arrays after
    (nearly) every state (the store's arrays grow by exactly what a call asks for) and by a
    full buffer of layer ends."""
    model = build(spec)
    ref = explore(model, compile_model(model, optimise=False), progress=False)
    monkeypatch.setattr(engine, "NATIVE_AFTER", after)
    monkeypatch.setattr(native, "MAX_EDGES", 7)

    class Tight(storage.Grow):
        def __init__(self, dtype, width=0, capacity=1):
            super().__init__(dtype, width, 1)

        def reserve(self, extra):
            if self.n + extra > len(self.data):
                self._resize(self.n + extra)
    monkeypatch.setattr(storage, "Grow", Tight)
    init = native.Native.__init__

    def one_layer(self, *a):          # a call ends after the first layer it began, as when its buffer is full
        init(self, *a)
        self.layers = self.layers[:1]
    monkeypatch.setattr(native.Native, "__init__", one_layer)
    calls = []
    bfs = native.Native.bfs
    monkeypatch.setattr(native.Native, "bfs", lambda self, *a: calls.append(a[1]) or bfs(self, *a))
    comp = compile_model(model)
    monkeypatch.setattr(comp.native, "cached", lambda: False)     # so the switch is at `after` states
    got = explore(model, comp, progress=False)
    assert comp.native() is not None and "compile" in got.times
    assert (bool(calls) and min(calls) == 0) == (after == 0)     # from the start, or after Python
    assert after or not got.ok or len(calls) >= got.states // 2   # stopped by full arrays, not layers
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


def _dead_end() -> Model:
    """A trigger state whose run can end (a final state) before the goal: a liveness violation."""
    vs = [Var("x", 3), Var("g", 1)]
    rules = [Rule("go", "x < 2", (("x", "x + 1"),), actor="a", ticks=2),
             Rule("hit", "x == 1", (("g", "1"), ("x", "3")), actor="a", ticks=5)]
    return Model("dead_end", vs, rules, final="x >= 2", responses=[Response("goal", "x == 1", "g == 1")])


def _random_responses(seed: int) -> Model:
    """A random graph over small counters with many random responses: bounded ones, cycles fair
    and unfair, dead ends -- every verdict of the response check occurs."""
    rng = random.Random(seed)
    hi = {"a": 5, "b": 5, "c": 1}
    vs = [Var(n, h) for n, h in hi.items()]
    rules = []
    for k in range(12):
        v, w = rng.choice(list(hi)), rng.choice(list(hi))
        guard = f"{w} {rng.choice(('==', '!=', '<', '>'))} {rng.randint(0, hi[w])}"
        effect = rng.choice((f"({v} + 1) % {hi[v] + 1}", str(rng.randint(0, hi[v])), f"{hi[v]} - {v}",
                             f"({v} + {w}) % {hi[v] + 1}"))
        rules.append(Rule(f"r{k}", guard, ((v, effect),), actor=rng.choice(("p", "q", None)),
                          ticks=rng.randint(0, 3)))
    cmp = ("==", "!=", "<", ">")
    responses = [Response(f"resp{k}", f"{rng.choice('ab')} {rng.choice(cmp)} {rng.randint(0, 5)}",
                          f"{rng.choice('ab')} {rng.choice(cmp)} {rng.randint(0, 5)}") for k in range(40)]
    return Model(f"random{seed}", vs, rules, final="c == 1", responses=responses)


def _idle_loop() -> Model:
    """A self-loop of no fairness group after the trigger: a fair cycle of one state (its lasso
    goes round the self-loop)."""
    rules = [Rule("start", "a == 0", (("a", "1"),), actor="p", ticks=1), Rule("idle", "a == 1", (("a", "1"),))]
    return Model("idle_loop", [Var("a", 2)], rules, responses=[Response("back", "a == 1", "a == 2")])


RESPONDING = [("idle-loop", lambda s: _idle_loop()), ("countdown", lambda s: toys.countdown(4)), ("countdown-stutter", lambda s: toys.countdown(4, True)),
              ("spin-forever", lambda s: toys.spin_forever()), ("dead-end", lambda s: _dead_end()),
              ("arb-colliders-2", lambda s: arbitration.build(sa.arbitration(s, "sensor", "colliders"), "spec", 2)),
              ("id-first-2", lambda s: id_retry.build(sa.identification(s, "first"), 2))] + [
              (f"random-{k}", lambda s, k=k: _random_responses(k)) for k in (0, 3, 4)]


@pytest.mark.parametrize("build", [b for _, b in RESPONDING], ids=[n for n, _ in RESPONDING])
def test_native_responses_decide_as_the_numpy_algorithm(spec, build, monkeypatch):
    """Per response, the C pass's verdict (bound K, fair-only, violation) is the numpy algorithm's,
    and a whole check gives the same bounds and counterexample on either."""
    model = build(spec)
    ref = explore(model, compile_model(model, optimise=False), progress=False)
    monkeypatch.setattr(engine, "NATIVE_AFTER", 0)
    got = explore(model, progress=False)
    assert got.native is not None and ref.native is None
    assert got.bounds == ref.bounds
    _same(got, ref)
    kinds = set()
    fast, graph = liveness._Native(ref), liveness._Graph(ref)
    fast.nat = got.native
    for index in range(len(model.responses)):
        bound, violation = liveness.check_response(ref, index, graph)
        kinds.add("violation" if violation else "fair-only" if bound is None else "bound")
        kind, k = fast.decide(index)
        assert (kind, k if kind == native.L_BOUND else None) == (
            (native.L_VIOLATION, None) if violation else
            (native.L_FAIR_ONLY, None) if bound is None else (native.L_BOUND, bound)), model.responses[index]
    if model.name.startswith("random"):
        assert kinds == {"violation", "fair-only", "bound"}, kinds
