"""The full 39-node POST, decided with symmetry reduction (issue 3; takes about a minute)."""
from model_check import spec_adapter as sa
from model_check.engine import explore
from model_check.models import post


def test_full_network_post_matches_oracle_everywhere(spec):
    model = post.build(sa.post(spec), legs=None, symmetry=True)
    assert len(model.vars) == len(spec.nodes) + 1     # every node has its NODES entry, plus the verdict
    res = explore(model, progress=False)
    assert res.ok, res.violation and res.violation.detail
    assert res.never_fired == []                      # every node was seen present, absent, mute, out of order
    assert {"verdict_HALTED", "verdict_DEGRADED", "verdict_OPERATIONAL"} <= {r.name for r in model.rules}
