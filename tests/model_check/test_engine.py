"""The engine on toy models whose answers are known by hand."""
from math import comb

import pytest

from model_check.compile import RangeError
from model_check.engine import explore
from model_check.expr import ExprError
from model_check.gcl import Model, Rule, Var
from tests.model_check import toys


def test_mutex_holds_and_counts_states():
    res = explore(toys.mutex(3), progress=False)
    # lock free: every pc in {0,2} (2^3); lock held: one process in 1, others in {0,2} (3 * 2^2)
    assert res.ok and res.states == 8 + 12
    assert res.never_fired == []


def test_broken_mutex_gives_shortest_counterexample():
    res = explore(toys.mutex(3, lock=False), progress=False)
    v = res.violation
    assert v is not None and v.kind == "invariant" and v.prop == "mutex"
    assert len(v.trace) == 3                       # initial state + two enters: the shortest way
    names = [res.model.rules[s.rule].name for s in v.trace[1:]]
    assert all(n.startswith("enter") for n in names) and len(set(names)) == 2


def test_deadlock_is_found_with_trace():
    res = explore(toys.dining(2), progress=False)
    v = res.violation
    assert v is not None and v.kind == "deadlock"
    last = res.compiled.layout.unpack(v.trace[-1].state)
    assert last == {"f0": 1, "f1": 1, "p0": 1, "p1": 1}
    assert res.compiled.successors(v.trace[-1].state) == []


def test_response_bound_is_longest_tick_path():
    res = explore(toys.countdown(5), progress=False)
    assert res.ok and res.bounds["reaches_zero"] == 5


def test_unfair_environment_loop_is_not_a_violation_but_has_no_bound():
    res = explore(toys.countdown(3, stutter=True), progress=False)
    assert res.ok
    assert res.bounds["reaches_zero"] is None      # holds under weak fairness only


def test_fair_cycle_gives_lasso():
    res = explore(toys.spin_forever(), progress=False)
    v = res.violation
    assert v is not None and v.kind == "liveness"
    loop = v.trace[v.loop_start:]
    assert len(loop) >= 2 and loop[0].state == loop[-1].state   # the cycle closes
    assert all(res.compiled.layout.unpack(s.state)["goal"] == 0 for s in v.trace)


def test_symmetry_reduces_to_orbits():
    plain = toys.tokens(4, 2)
    plain.symmetry = []
    full = explore(plain, progress=False)
    reduced = explore(toys.tokens(4, 2), progress=False)
    assert full.states == 3 ** 4
    assert reduced.states == comb(4 + 2, 4)        # multisets of 4 values from 3
    assert reduced.ok and full.ok


def test_symmetry_with_liveness_warns():
    m = toys.tokens(3, 1)
    m.responses = [toys.Response("x", "c0 == 0", "c0 == 1")]
    res = explore(m, progress=False)
    assert any("safety only" in w for w in res.warnings)


def test_out_of_range_effect_is_reported():
    m = Model("bad", [Var("x", 2)], [Rule("inc", "True", (("x", "x + 1"),))])
    with pytest.raises(RangeError):
        explore(m, progress=False)


@pytest.mark.parametrize("text", ["x.y", "x and 1 + 2", "f(x)", "[x]"])
def test_expressions_outside_the_shared_language_are_rejected(text):
    with pytest.raises(ExprError):
        Model("bad", [Var("x", 2)], [Rule("r", text)])


def test_coverage_lists_rules_that_never_fire():
    m = Model("cov", [Var("x", 1)], [Rule("go", "x == 0", (("x", "1"),)), Rule("never", "x == 2")], final="x == 1")
    res = explore(m, progress=False)
    assert res.ok and res.never_fired == ["never"]
