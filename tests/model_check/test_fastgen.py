"""The optimised `expand` (model_check.fastgen) against the plain reference generator.

They must agree exactly -- not only on counts but on the order of every layer,
the coverage, the visited set and the counterexamples -- because SPIN
cross-checks the counts and the traces are shown to users.
"""
import random

import pytest

from model_check import spec_adapter as sa
from model_check.compile import RangeError, compile_model
from model_check.engine import explore
from model_check.gcl import Invariant, Model, Rule, Var
from model_check.models import arbitration, id_retry, post
from tests.model_check import toys


def _sequential() -> Model:
    """Effects that read earlier assignments, a definition, constants and a terminal state."""
    vs = [Var("a", 3), Var("b", 3), Var("c", 7), Var("d", 1)]
    rules = [Rule("ab", "a < 3 and d == 0", (("a", "a + 1"), ("b", "a"))),
             Rule("twice", "b == 1 and c < 6", (("c", "c + 1"), ("c", "c + 1"))),
             Rule("const", "tot >= 4 and d == 0", (("d", "1"), ("a", "0"), ("b", "2 - 1"))),
             Rule("reset", "d == 1 and c != 0", (("c", "min(c, 3) - 1 if c > 0 else 0"),)),
             Rule("never", "False", (("a", "1"),))]
    return Model("sequential", vs, rules, [Invariant("bounded", "tot <= 13")], final="d == 1 and c == 0",
                 defs=[("tot", "a + b + c")])


MODELS = [
    ("mutex", lambda s: toys.mutex(3)),
    ("mutex-broken", lambda s: toys.mutex(3, lock=False)),
    ("dining", lambda s: toys.dining(3)),
    ("countdown", lambda s: toys.countdown(4, stutter=True)),
    ("spin-forever", lambda s: toys.spin_forever()),
    ("tokens-sym", lambda s: toys.tokens(4, 2)),
    ("sequential", lambda s: _sequential()),
    ("arb-seed-2", lambda s: arbitration.build(sa.arbitration(s, "sensor"), "seed", 2)),
    ("arb-sensor-all-3", lambda s: arbitration.build(sa.arbitration(s, "sensor", "all"), "spec", 3)),
    ("arb-colliders-2", lambda s: arbitration.build(sa.arbitration(s, "sensor", "colliders"), "spec", 2)),
    ("arb-colliders-4", lambda s: arbitration.build(sa.arbitration(s, "sensor", "colliders"), "spec", 4)),
    ("arb-first-all", lambda s: arbitration.build(sa.arbitration(s, "first", "all"), "spec")),
    ("id-first-2", lambda s: id_retry.build(sa.identification(s, "first"), 2)),
    ("post-1-leg", lambda s: post.build(sa.post(s), legs=1, symmetry=False)),
]


def _no_bound(model: Model) -> Model:
    model.invariants = [i for i in model.invariants if i.name != "collisions_bounded"]
    return model


def _same(a, b) -> None:
    assert (a.states, a.transitions, a.depth) == (b.states, b.transitions, b.depth)
    assert a.coverage == b.coverage
    assert a.layers == b.layers                      # same order, so the same traces
    assert a.seen == b.seen and list(a.seen) == list(b.seen)
    assert a.bounds == b.bounds
    assert (a.violation is None) == (b.violation is None)
    if a.violation is not None:
        va, vb = a.violation, b.violation
        assert (va.kind, va.prop, va.loop_start, va.detail) == (vb.kind, vb.prop, vb.loop_start, vb.detail)
        assert [(s.rule, s.state) for s in va.trace] == [(s.rule, s.state) for s in vb.trace]


@pytest.mark.parametrize("build", [b for _, b in MODELS], ids=[n for n, _ in MODELS])
def test_optimised_search_equals_reference(spec, build):
    model = build(spec)
    fast = explore(model, compile_model(model), progress=False)
    ref = explore(model, compile_model(model, optimise=False), progress=False)
    _same(fast, ref)
    if model.invariants and any(i.name == "collisions_bounded" for i in model.invariants):
        model = _no_bound(build(spec))
        _same(explore(model, compile_model(model), progress=False),
              explore(model, compile_model(model, optimise=False), progress=False))


def _reference_step(comp, model, s):
    """What one expansion of `s` must give: (hit, successors in order, per-rule counts)."""
    for i, _ in enumerate(model.invariants):
        if not comp.predicates[f"inv{i}"](s):
            return ("invariant", i, s), [], [0] * len(model.rules)
    succ = comp.successors(s)
    counts = [0] * len(model.rules)
    out = []
    for rule, ns in succ:
        counts[rule] += 1
        ns = comp.canon(ns)
        if ns not in out:
            out.append(ns)
    if not succ and not comp.predicates["final"](s):
        return ("deadlock", -1, s), [], counts
    return None, out, counts


@pytest.mark.parametrize("build", [b for _, b in MODELS], ids=[n for n, _ in MODELS])
def test_successors_of_random_states_equal_reference(spec, build):
    """Arbitrary in-range states, reachable or not, twice over so the memo tables are hit too."""
    model = build(spec)
    comp = compile_model(model)
    rng = random.Random(3)
    states = [comp.layout.pack({v.name: rng.randint(0, v.hi) for v in model.vars}) for _ in range(400)]
    for s in states + states:
        try:
            want = _reference_step(comp, model, s)
        except RangeError:
            with pytest.raises(RangeError):
                comp.expand([s], set(), [0] * len(model.rules))
            continue
        cov = [0] * len(model.rules)
        got, hit = comp.expand([s], set(), cov)
        assert (hit, got, cov) == want, hex(s)


def test_reference_model_source_is_specialised(spec):
    """The bench model: guards are sorted by the master's phase, no per-state decode of every field."""
    model = arbitration.build(sa.arbitration(spec, "sensor", "colliders"), "spec", 7)
    src = compile_model(model).source
    body = src[src.index("def expand"):src.index("def successors")]
    assert "v_mph == 0" in body and ".get(" in body
    assert body.count("v_col3 = ") < body.count("app(ns)")
