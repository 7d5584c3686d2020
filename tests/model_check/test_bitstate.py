"""Bitstate search (issue 12, item 5): its losses match the printed estimate on a known space."""
import math

import pytest

from model_check.bitstate import HASHES, expected_omissions, explore_bitstate
from model_check.engine import explore

from tests.model_check import toys


@pytest.mark.parametrize("bits", [18, 19, 20])
def test_omitted_states_match_the_estimate_on_a_space_of_known_size(bits):
    """The torus has 16**4 = 65,536 states, each reachable from 8 others, so a lost state costs only
    itself: the states missed must be the printed expectation within Poisson noise."""
    model = toys.torus(4, 16)
    full = explore(model, progress=False)
    assert full.states == 16 ** 4
    res, est = explore_bitstate(model, bits, progress=False)
    missed = full.states - res.states
    assert missed > 0                                    # these sizes do lose states: the test can fail
    assert abs(missed - est.expected_omitted) <= 3 * math.sqrt(est.expected_omitted) + 0.02 * est.expected_omitted
    assert abs(res.states / full.states - est.coverage) < 0.003
    assert not res.proof and res.ok
    assert "NOT a proof" in res.warnings[-1] and f"2^{bits} bits" in res.warnings[-1]


def test_a_big_table_finds_the_whole_space_and_the_same_violations():
    model = toys.mutex(3, lock=False)
    want = explore(model, progress=False)
    res, est = explore_bitstate(model, 24, progress=False)
    assert not want.ok and not res.ok
    assert (res.violation.kind, res.violation.prop) == (want.violation.kind, want.violation.prop)
    dining = toys.dining(3)
    res, _ = explore_bitstate(dining, 24, progress=False)
    assert res.violation is not None and res.violation.kind == "deadlock"
    full = explore(toys.tokens(4, 3), progress=False)
    res, est = explore_bitstate(toys.tokens(4, 3), 24, progress=False)
    assert (res.states, res.transitions, res.depth, res.coverage) == \
        (full.states, full.transitions, full.depth, full.coverage)
    assert est.expected_omitted < 1e-3


def test_the_formula():
    """p_i = (1 - e^(-k i / m))^k summed: one state in an empty table is never lost."""
    assert expected_omissions(1, 1 << 10, HASHES) == (0.0, pytest.approx((1 - math.exp(-HASHES / 1024)) ** HASHES))
    total, last = expected_omissions(1000, 1 << 12, HASHES)
    want = sum((1 - math.exp(-HASHES * i / 4096)) ** HASHES for i in range(1000))
    assert total == pytest.approx(want) and last == pytest.approx((1 - math.exp(-HASHES * 1000 / 4096)) ** HASHES)


def test_cli_prints_the_estimate_and_refuses_bad_sizes(capsys):
    from arachnae.cli import main
    rc = main(["check", "id_retry", "--bus", "sensor", "--size", "2", "--bitstate", "20", "--quiet"])
    out = capsys.readouterr().out
    assert rc == 0
    assert "hash factor" in out and "NOT a proof" in out and "ALL PROPERTIES HOLD" not in out
    with pytest.raises(SystemExit) as exc:
        main(["check", "id_retry", "--bitstate", "99"])
    assert exc.value.code == 2 and "--bitstate: must be 10 .. 36" in capsys.readouterr().err


@pytest.mark.parametrize("bits", [22, 24])
def test_hash_compact_omissions_match_the_birthday_estimate(bits):
    """Hash-compact (--hash-compact): b-bit signatures of the 65,536 torus states; two that share one are
    taken for one, about n(n-1)/2^(b+1) of them, and a lost torus state costs only itself."""
    from model_check.bitstate import explore_hash_compact

    model = toys.torus(4, 16)
    full = explore(model, progress=False)
    res, est = explore_hash_compact(model, bits, progress=False)
    missed = full.states - res.states
    assert missed > 0                                    # these sizes do lose states: the test can fail
    assert abs(missed - est.expected_omitted) <= 3 * math.sqrt(est.expected_omitted) + 0.02 * est.expected_omitted
    assert not res.proof and res.ok and "NOT a proof" in res.warnings[-1]
    assert res.store_bytes == 8 * res.states             # one signature a state


def test_hash_compact_with_wide_signatures_finds_the_whole_space_and_the_violations():
    from model_check.bitstate import explore_hash_compact

    full = explore(toys.tokens(4, 3), progress=False)
    res, est = explore_hash_compact(toys.tokens(4, 3), 64, progress=False)
    assert (res.states, res.transitions, res.depth, res.coverage) == \
        (full.states, full.transitions, full.depth, full.coverage)
    want = explore(toys.mutex(3, lock=False), progress=False)
    res, _ = explore_hash_compact(toys.mutex(3, lock=False), 64, progress=False)
    assert (res.violation.kind, res.violation.prop) == (want.violation.kind, want.violation.prop)
