"""The parallel search (issue 12, item 4) against the sequential one: same counts, same verdicts."""
import pytest

from model_check import spec_adapter as sa
from model_check.checks import build_models
from model_check.engine import explore
from model_check.parallel import explore_parallel
from tests.model_check import toys


def _models():
    spec = sa.load()
    yield from build_models("id_retry", spec, size=3)                    # both buses
    yield from build_models("arbitration", spec, bus="sensor", size=3)
    yield from build_models("arbitration", spec, variant="seed", bus="first", size=2)
    yield from build_models("post", spec, legs=1)                        # symmetry reduction
    yield from build_models("reaction", spec, size=1)
    yield toys.tokens(4, 3)
    yield toys.mutex(3, lock=False)                                      # invariant violated
    yield toys.dining(3)                                                 # deadlock


@pytest.mark.parametrize("workers", [2, 3])
def test_parallel_equals_sequential(workers):
    for model in _models():
        seq = explore(model, progress=False, check_liveness=False)
        par = explore_parallel(model, workers, progress=False)
        assert par.ok == seq.ok, model.name
        if seq.ok:
            assert (par.states, par.transitions, par.depth, par.coverage) == \
                (seq.states, seq.transitions, seq.depth, seq.coverage), model.name
            assert par.store_bytes > 0 and par.cpu > 0
        else:
            v, w = par.violation, seq.violation
            assert (v.kind, v.prop) == (w.kind, w.prop), model.name
            assert [s.state for s in v.trace] == [s.state for s in w.trace]
            assert par.depth == seq.depth, model.name       # it stopped in the same layer


def test_cli_runs_the_parallel_search(capsys):
    from arachnae.cli import main
    assert main(["check", "id_retry", "--bus", "sensor", "--size", "2", "--workers", "2", "--quiet"]) == 0
    out = capsys.readouterr().out
    assert "SAFETY PROPERTIES HOLD (responses not checked)" in out and "parallel search (2 workers)" in out
    assert main(["check", "id_retry", "--workers", "2", "--bitstate", "20"]) == 1
    assert "choose one" in capsys.readouterr().err
