"""report.html of every `sim run`, checked in headless Chromium and against the run's own outputs (issue 13)."""
from __future__ import annotations

import csv
import json
import re

from sim2d.report import LOAD_BINS, bus_load, sequences

from .conftest import offline, open_page


def test_report_in_chromium(browser, report_run, tmp_path):
    metrics = json.loads((report_run / "metrics.json").read_text())
    control = list(csv.DictReader(open(report_run / "control.tsv"), delimiter="\t"))
    loaded = open_page(browser, report_run / "report.html")
    page = loaded.page
    page.screenshot(path=str(tmp_path / "report.png"), full_page=True)
    assert (tmp_path / "report.png").stat().st_size > 20_000
    # the world and its legend: pits, lights, slopes, heat, obstacles by height
    for cls, n in (("pit", 1), ("light", 1), ("slope", 1), ("heat", 1), ("obstacle", 2), ("region.forbidden", 1)):
        assert page.locator(f"#world .{cls}").count() == n, cls
    legend = page.inner_text("#legend")
    for text in ("pit", "light", "slope", "obstacle 0.03 m (stepped over)", "obstacle 0.12 m (too high to step over)"):
        assert text in legend
    # the time slider moves the robot to the first logged pose and the cursors to t = 0
    poses = json.loads(page.inner_text("#poses"))
    page.eval_on_selector("#time", "el => { el.value = 0; el.dispatchEvent(new Event('input')); }")
    moved = [float(v) for v in re.findall(r"-?[\d.]+", page.get_attribute("#robot", "transform"))]
    assert moved == [poses[0][1], poses[0][2], -poses[0][3]] and moved != [poses[-1][1], poses[-1][2], -poses[-1][3]]
    assert page.inner_text("#time-label") == "0.0 s"
    assert set(page.eval_on_selector_all("line.cursor", "els => els.map(e => e.getAttribute('x1'))")) == {"110"}
    # the control timeline: one bar per interval of control.tsv
    assert page.locator("#control-chart rect.interval").count() == len(control) >= 3
    # bus load: a chart per bus
    assert page.eval_on_selector_all("#bus-load-chart polygon.load", "els => els.map(e => e.dataset.bus)") == list(metrics["buses"])
    # one sequence chart per reaction, with the frames around it
    assert len(metrics["reactions"]) >= 1
    assert page.locator("svg.sequence").count() == len(metrics["reactions"])
    assert page.locator("svg.sequence line.frame").count() > 10
    assert "MOVE_RELAYED" in page.text_content("svg.sequence")
    # metrics and expectations, and the run's picture, inline
    assert page.locator("#expectations td.pass").count() == len(metrics["expectations"]) >= 4   # with protocol.violations
    assert page.evaluate("Array.from(document.images).every(i => i.complete && i.naturalWidth > 0)")
    assert page.locator("img.picture").count() >= 1
    assert loaded.errors == [] and offline(loaded.requests)


def test_bus_load_and_sequences_come_from_the_trace(report_outcome, spec):
    """The load chart's bins average to each bus's load in metrics.json; the sequence charts hold the
    frames of the event-driven buses around each reaction, up to the MOVE reaching the MMC."""
    outcome = report_outcome
    m = outcome.result.metrics
    load = bus_load(outcome.result.frames, list(m["buses"]), outcome.scenario.duration)
    for bus, bins in load.items():
        assert len(bins) == LOAD_BINS and all(0 <= v <= 1 for v in bins)
        assert abs(sum(bins) / LOAD_BINS - m["buses"][bus]["load"]) < 0.002, bus
    seqs = sequences(sorted(outcome.result.frames, key=lambda f: f.start), m["reactions"], spec)
    request_buses = {b.name for b in spec.buses.values() if b.request_message}
    assert len(seqs) == len(m["reactions"]) >= 1
    for s in seqs:
        r = s.reaction
        assert s.arrows and {a.bus for a in s.arrows} <= request_buses
        assert all(r["stimulus_s"] - 0.05 <= a.time <= r["move_s"] + 0.05 for a in s.arrows)
        assert any(a.label == "MOVE_RELAYED" and a.dst == "MMC" for a in s.arrows)


def test_report_escapes_scenario_text_and_shows_no_control_when_there_is_none(report_outcome, tmp_path):
    from dataclasses import replace

    from sim2d.report import write_report

    evil = '<img src=x onerror="window.__pwned=1">'
    outcome = replace(report_outcome, scenario=replace(report_outcome.scenario, name=evil))
    html = write_report(outcome, tmp_path).read_text()
    assert evil not in html and "&lt;img src=x onerror=&#34;window.__pwned=1&#34;&gt;" in html
    assert "No control trace" in html                      # this folder has no control.tsv
