"""SPIN on the emitted Promela must agree with our checker: verdicts and stored-state counts.

Our states equal SPIN's stored states exactly: the emitted proctype never
leaves its loop head (one d_step per transition, all state global), and the
invariant / deadlock alternatives only fire on a violation, so they add no
state in a passing run. No off-by-one correction is applied.
"""
import pytest

from model_check import promela, spin
from model_check import spec_adapter as sa
from model_check.engine import explore
from model_check.models import arbitration, id_retry, post
from tests.model_check import toys


def _both(model, **kw):
    ours = explore(model, progress=False)
    theirs = spin.run(promela.emit(model), depth_limit=max(10_000, 4 * ours.states), **kw)
    return ours, theirs


def test_spin_is_installed():
    assert spin.available(), "install SPIN: apt-get install -y spin"


@pytest.mark.parametrize("build", [
    lambda s: toys.mutex(3),
    lambda s: arbitration.build(sa.arbitration(s, "sensor", "all"), "spec", 4),
    lambda s: arbitration.build(sa.arbitration(s, "first", "all"), "spec"),
    lambda s: arbitration.build(sa.arbitration(s, "sensor", "colliders"), "spec", 3),
    lambda s: id_retry.build(sa.identification(s, "first"), 2),
    lambda s: id_retry.build(sa.identification(s, "sensor"), 2),
    lambda s: post.build(sa.post(s), legs=1, symmetry=False),
], ids=["mutex", "arb-sensor-4", "arb-first", "arb-colliders-3", "id-first-2", "id-sensor-2", "post-1-leg"])
def test_same_verdict_and_state_count(spec, build):
    model = build(spec)
    model.responses = []            # liveness is cross-checked separately (claims change SPIN's counts)
    ours, theirs = _both(model)
    assert (theirs.errors == 0) == ours.ok
    if ours.ok:
        assert theirs.stored == ours.states


@pytest.mark.parametrize("model", [toys.mutex(3, lock=False), toys.dining(2)], ids=["mutex-broken", "dining"])
def test_spin_also_finds_safety_violations(model):
    ours, theirs = _both(model)
    assert not ours.ok and theirs.errors > 0


def test_liveness_verdicts_agree(spec):
    seed = arbitration.build(sa.arbitration(spec, "sensor"), "seed", 2)
    good = arbitration.build(sa.arbitration(spec, "sensor", "all"), "spec", 3)
    for model, holds in ((seed, False), (good, True)):
        ours = explore(model, progress=False)
        assert ours.ok is holds
        for i, r in enumerate(model.responses):
            res = spin.run(promela.emit(model, ltl=i), liveness=r.name)
            assert (res.errors == 0) is holds, r.name
            if not holds:
                break


def test_too_small_depth_limit_is_an_error(spec):
    from arachnae.errors import UserError
    model = id_retry.build(sa.identification(spec, "first"), 1)
    with pytest.raises(UserError, match="depth"):
        spin.run(promela.emit(model), depth_limit=5)
