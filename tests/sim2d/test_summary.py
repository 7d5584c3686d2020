"""The batch summary table: one row per run, PASS only when every expectation passed."""
from __future__ import annotations

from sim2d.summary import markdown


def _metrics(name: str, seed: int, passed: list[bool], control: dict | None = None) -> dict:
    return {"scenario": name, "seed": seed, "post": {"verdict": "OPERATIONAL"}, "distance_walked_m": 1.234,
            "collisions": 0, "min_clearance_m": 0.25, "max_reaction_s": 0.412,
            "nodes": {"NP3": {"control": control}} if control else {},
            "notes": {"escape": {"count": 3}},
            "expectations": [{"name": f"e{i}", "passed": p, "detail": ""} for i, p in enumerate(passed)]}


def test_rows_sorted_with_pass_fail_and_key_metrics() -> None:
    table = markdown([_metrics("b", 2, [True, False]), _metrics("a", 1, [True], {"reflexes": 2.0, "task": 30.4})])
    lines = table.splitlines()
    assert lines[2].startswith("| a | 1 | PASS | OPERATIONAL | 1.23 | 0 | 0.25 | 0.41 | 2/0/30 | - | - | escape=3 |")
    assert lines[3].startswith("| b | 2 | FAIL |")
    assert len(lines) == 4


def test_battery_columns_show_the_sag_and_the_psc_alarms() -> None:
    """Issue 18: a load dip the PSC took for under-voltage shows in the table at a glance."""
    m = _metrics("a", 1, [True])
    m["battery"] = {"v_min": 4.183, "v_mean": 4.66, "v_final": 4.702, "psc_mean_min_v": 4.225,
                    "psc_level_min_v": 4.43, "psc_alarms": 1}
    cells = markdown([m]).splitlines()[2].split(" | ")
    assert cells[9:11] == ["4.18/4.66/4.70", "4.22/4.43, 1"]
    m["battery"].update(psc_mean_min_v=None, psc_level_min_v=None, psc_alarms=None)   # no PSC (optional node)
    assert markdown([m]).splitlines()[2].split(" | ")[10] == "-"


def test_protocol_column_shows_violations_and_the_wait_against_k() -> None:
    """Issue 11: a run whose trace broke the verified protocol shows it in the table, with each contended
    bus's longest wait against the checker's K."""
    m = _metrics("a", 1, [True])
    assert markdown([m]).splitlines()[2].split(" | ")[-1] == "- |"
    m["protocol"] = {"violations": 2, "max_wait_slots": {"first": 39.02, "sensor": 4.0},
                     "k_slots": {"first": 36, "sensor": 32}}
    assert markdown([m]).splitlines()[2].split(" | ")[-1] == "2; first 39.0/36 sensor 4.0/32 |"
