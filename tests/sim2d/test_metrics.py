"""The 5.2 reaction metric's definition (sim2d.metrics.reactions), case by case."""
from __future__ import annotations

import pytest

from sim2d.metrics import check_expectations, lookup, reactions
from sim2d.scenario import Expectations, NoteOrder

FWD, BACK, LEFT = 1, 2, 4


def reaction_latencies(*args: object) -> list[float]:
    return [r["latency_s"] for r in reactions(*args)]  # type: ignore[arg-type]


def test_a_stimulus_is_answered_by_the_first_move_of_the_manoeuvre_it_started():
    # the task's FORWARD at 3.1 happens to follow; the reaction is the MOVE after the manoeuvre began at 3.2
    lat = reaction_latencies([(3.0, "whisker")], [(1.0, FWD), (3.1, FWD), (3.3, BACK)], [(3.2, 5.0)], 1.0, 10.0)
    assert lat == [pytest.approx(0.3)]


def test_a_stimulus_during_post_counts_from_the_start_of_navigation():
    lat = reaction_latencies([(0.0, "ir"), (0.02, "whisker")], [(1.4, FWD), (1.7, BACK)], [(1.6, 3.0)], 1.3, 10.0)
    assert lat == [pytest.approx(1.7 - 1.3)]          # both answered by one reaction


def test_stimuli_while_a_manoeuvre_runs_are_already_being_handled():
    stimuli = [(2.0, "whisker"), (2.5, "ir"), (3.9, "whisker")]
    lat = reaction_latencies(stimuli, [(2.1, BACK), (3.0, LEFT)], [(2.05, 4.0)], 1.0, 10.0)
    assert lat == [pytest.approx(0.1)]


def test_a_stimulus_never_answered_fails_with_the_rest_of_the_run():
    lat = reaction_latencies([(5.0, "whisker")], [(1.0, FWD)], [], 1.0, 9.0)
    assert lat == [pytest.approx(4.0)]
    assert reaction_latencies([(8.5, "whisker")], [(1.0, FWD)], [], 1.0, 9.0) == []   # the run ended too soon


def test_nothing_counts_when_navigation_never_started():
    assert reaction_latencies([(1.0, "whisker")], [(1.5, BACK)], [(1.2, 2.0)], None, 9.0) == []


def test_each_reaction_record_names_its_stimulus_and_whether_it_was_answered():
    recs = reactions([(3.0, "whisker"), (6.0, "ir")], [(3.3, BACK)], [(3.2, 5.0)], 1.0, 9.0)
    assert [(r["kind"], r["stimulus_s"], r["move_s"], r["answered"]) for r in recs] == [
        ("whisker", 3.0, 3.3, True), ("ir", 6.0, 9.0, False)]


def test_a_note_never_written_counts_zero_and_other_absent_metrics_are_none():
    """A scenario can expect that something never happened (scenarios/sonar_first.yaml: no close-up stimulus)."""
    m = {"notes": {"escape": {"count": 2, "first_s": 1.0}}, "nodes": {}}
    assert lookup(m, "notes.escape.count") == 2 and lookup(m, "notes.stimulus.count") == 0
    assert lookup(m, "notes.stimulus.first_s") is None and lookup(m, "nodes.NP3.map.routes") is None


def _order_verdict(notes: dict[str, dict[str, float]]) -> tuple[bool, str]:
    scenario = type("S", (), {"expect": Expectations(order=NoteOrder("escape", "stimulus"))})()
    [(name, ok, detail)] = check_expectations(scenario, {"notes": notes})
    assert name == "order"
    return ok, detail


def test_order_holds_when_the_first_note_comes_before_any_of_the_second_or_none_comes():
    """sonar_first: the sonar's avoidance (escape) before any close-up stimulus; a touch later does not matter."""
    assert _order_verdict({"escape": {"first_s": 13.0}, "stimulus": {"first_s": 20.4}})[0]
    assert _order_verdict({"escape": {"first_s": 13.0}})[0]


def test_order_fails_when_the_second_note_comes_first_or_the_first_never_does():
    ok, detail = _order_verdict({"escape": {"first_s": 13.0}, "stimulus": {"first_s": 12.9}})
    assert not ok and detail == "first escape at 13.0 s, first stimulus at 12.9 s"
    assert not _order_verdict({"stimulus": {"first_s": 5.0}})[0]
    assert not _order_verdict({})[0]
