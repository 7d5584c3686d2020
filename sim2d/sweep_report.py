"""`arachnae sweep report RESULTS` (issue 14): how often a sweep's expectations hold, and what predicts failure.

Pass rate per expectation with a Wilson 95 % interval (sound at small counts and at 0 % / 100 %, where the
normal approximation collapses); failure rate per parameter bin; a table per base scenario (passes, which
expectation failed on which seeds, worst reaction, collisions, falls); the spread of each collected metric per
scenario (what a builder sets an expectation from: issue 16 item 7); the worst runs with their replay command.
Written as report.md and as report.html (the run report's page style, plots inlined, each worst run linked to
its own run report in failed/RUN/), with PNG bar charts (Pillow, already a dependency) in plots/.
"""
from __future__ import annotations

import math
import statistics
from collections import Counter
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from arachnae.files import atomic_open
from codegen.html import write_page
from sim2d.report import TEMPLATES, data_uri
from sim2d.sweep import read_table

Z95 = 1.959963984540054          # two-sided 95 % quantile of the normal distribution
MAX_BINS = 5
WORST = 10


@dataclass(frozen=True)
class Rate:
    label: str
    n: int
    k: int                       # successes (passes, or failures for a failure rate)

    @property
    def rate(self) -> float:
        return self.k / self.n if self.n else 0.0

    @property
    def interval(self) -> tuple[float, float]:
        return wilson(self.k, self.n)

    @property
    def text(self) -> str:
        """`50.0 % [15.0, 85.0]`: the rate and its Wilson 95 % interval, in percent."""
        lo, hi = self.interval
        return f"{100 * self.rate:.1f} % [{100 * lo:.1f}, {100 * hi:.1f}]"


@dataclass(frozen=True)
class ParamRates:
    """The failure rates per bin of one varied parameter, with its chart as a data: URI for the page."""

    name: str
    rates: list[Rate]
    plot: str | None


def wilson(k: int, n: int, z: float = Z95) -> tuple[float, float]:
    """Wilson score interval of a proportion k/n (0..1); (0, 1) when n is 0."""
    if n == 0:
        return (0.0, 1.0)
    p = k / n
    denom = 1 + z * z / n
    centre = (p + z * z / (2 * n)) / denom
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / denom
    return (max(0.0, centre - half), min(1.0, centre + half))


def pass_rates(rows: list[dict[str, Any]]) -> list[Rate]:
    """One Rate per expectation column (runs where the scenario declares it), then all expectations together."""
    names = [k for k in (rows[0] if rows else {}) if k.startswith("expect.")]
    out = []
    for name in names:
        vals = [r[name] for r in rows if r[name] is not None]
        out.append(Rate(name.removeprefix("expect."), len(vals), sum(bool(v) for v in vals)))
    out.append(Rate("all expectations", len(rows), sum(bool(r["passed"]) for r in rows)))
    return out


def _bins(values: list[Any]) -> list[tuple[str, Any]]:
    """(label, membership test) per bin: each value when there are few or they are not numbers, else equal widths."""
    distinct = sorted({v for v in values if v is not None}, key=lambda v: (str(type(v)), v))
    numeric = all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in distinct)
    if not numeric or len(distinct) <= MAX_BINS:
        return [(str(v), (lambda x, v=v: x == v)) for v in distinct]
    lo, hi = float(distinct[0]), float(distinct[-1])
    width = (hi - lo) / MAX_BINS
    out = []
    for i in range(MAX_BINS):
        a, b = lo + i * width, lo + (i + 1) * width
        last = i == MAX_BINS - 1
        out.append((f"[{a:g}, {b:g}{']' if last else ')'}",
                    (lambda x, a=a, b=b, last=last: x is not None and a <= x and (x <= b if last else x < b))))
    return out


def failure_by_parameter(rows: list[dict[str, Any]]) -> dict[str, list[Rate]]:
    """Failure rate per bin of each varied parameter, and per base scenario."""
    columns = ["scenario"] + [k for k in (rows[0] if rows else {}) if k.startswith("param.")]
    out: dict[str, list[Rate]] = {}
    for col in columns:
        rates = []
        for label, member in _bins([r[col] for r in rows]):
            inside = [r for r in rows if member(r[col])]
            rates.append(Rate(label, len(inside), sum(not r["passed"] for r in inside)))
        out[col.removeprefix("param.")] = rates
    return out


@dataclass(frozen=True)
class Spread:
    """One collected metric over one scenario's runs: numbers as min / median / max, flags and words as counts."""

    scenario: str
    metric: str
    n: int                       # runs that gave a value
    text: str


def _spread_text(values: list[Any]) -> str:
    """`0.41 / 0.52 / 0.9` for numbers, `3 of 20` for flags, `NORMAL 18, DEGRADED 2` for anything else."""
    if all(isinstance(v, bool) for v in values):
        return f"{sum(values)} of {len(values)}"
    if all(isinstance(v, (int, float)) for v in values):
        return " / ".join(f"{round(float(x), 3):g}" for x in (min(values), statistics.median(values), max(values)))
    return ", ".join(f"{v} {k}" for v, k in Counter(map(str, values)).most_common())


def metric_spread(rows: list[dict[str, Any]]) -> list[Spread]:
    """Per base scenario and collected metric, the spread of the values the runs gave (runs with none are left out)."""
    metrics = [k for k in (rows[0] if rows else {}) if k.startswith("metric.")]
    out = []
    for scenario in sorted({r["scenario"] for r in rows}):
        mine = [r for r in rows if r["scenario"] == scenario]
        for col in metrics:
            values = [r[col] for r in mine if r[col] is not None]
            if values:
                out.append(Spread(scenario, col.removeprefix("metric."), len(values), _spread_text(values)))
    return out


@dataclass(frozen=True)
class WorstRun:
    """A failing run as the report lists it: what failed, how to replay it, and its own run report if kept."""

    run_id: str
    scenario: str
    seed: int
    params: str
    failed: str
    replay: str
    report: str | None           # failed/RUN/report.html, relative to the results folder


def worst_runs(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Failing runs, most expectations failed first (errors first of all), then by run id."""
    failing = [r for r in rows if not r["passed"]]
    return sorted(failing, key=lambda r: (r["error"] is None, -len((r["failed"] or "").split(", ")),
                                          r["run_id"]))[:WORST]


def _worst(results: Path, rows: list[dict[str, Any]]) -> list[WorstRun]:
    out = []
    for r in worst_runs(rows):
        page = Path("failed") / r["run_id"] / "report.html"
        out.append(WorstRun(r["run_id"], r["scenario"], r["seed"],
                            ", ".join(f"{k.removeprefix('param.')}={v}" for k, v in r.items() if k.startswith("param.")),
                            r["error"] or r["failed"], r["replay"], str(page) if (results / page).is_file() else None))
    return out


@dataclass(frozen=True)
class ScenarioRow:
    """One base scenario's runs: the pass table the session note carries (issue 14 item 5, issue 17)."""
    scenario: str
    runs: int
    passed: int
    failures: dict[str, list[int]]       # expectation -> seeds it failed on
    worst_reaction: tuple[float, int] | None    # (max_reaction_s, seed), None: no stimulus or not collected
    collided: tuple[int, int] | None     # (runs with a collision, most contacts in one run), None: not collected
    falls: int | None                    # runs that fell, None: not collected


def per_scenario(rows: list[dict[str, Any]]) -> list[ScenarioRow]:
    """Per base scenario, in table order: passes, which expectation failed on which seeds, the worst reaction,
    collisions and falls (the last three only when the sweep collected max_reaction_s, collisions, fell)."""
    out = []
    for name in dict.fromkeys(r["scenario"] for r in rows):
        mine = [r for r in rows if r["scenario"] == name]
        failures: dict[str, list[int]] = {}
        for r in mine:
            for key, ok in r.items():
                if key.startswith("expect.") and ok is False:
                    failures.setdefault(key.removeprefix("expect."), []).append(r["seed"])
            if r["error"]:
                failures.setdefault("error", []).append(r["seed"])
        reactions = [(r["metric.max_reaction_s"], r["seed"]) for r in mine if r.get("metric.max_reaction_s") is not None]
        contacts = [r["metric.collisions"] for r in mine if r.get("metric.collisions") is not None]
        fell = [r["metric.fell"] for r in mine if r.get("metric.fell") is not None]
        out.append(ScenarioRow(Path(name).stem, len(mine), sum(bool(r["passed"]) for r in mine), failures,
                               max(reactions) if reactions else None,
                               (sum(c > 0 for c in contacts), max(contacts)) if contacts else None,
                               sum(bool(f) for f in fell) if fell else None))
    return out


def _seed_list(seeds: list[int]) -> str:
    return ", ".join(str(s) for s in sorted(seeds))


SCENARIO_HEAD = ["scenario", "passed", "failed expectations (seeds)", "worst reaction", "collisions (runs, most contacts)",
                 "falls"]


def scenario_cells(rows: list[dict[str, Any]]) -> list[list[str]]:
    """The per-scenario table's cells (SCENARIO_HEAD's columns), for report.md and report.html alike."""
    lines = []
    for s in per_scenario(rows):
        failed = "; ".join(f"{n} ({_seed_list(seeds)})" for n, seeds in s.failures.items()) or "-"
        reaction = f"{s.worst_reaction[0]:.2f} s (seed {s.worst_reaction[1]})" if s.worst_reaction else "-"
        collided = f"{s.collided[0]} runs, {s.collided[1]}" if s.collided and s.collided[0] else \
            ("0" if s.collided else "-")
        lines.append([s.scenario, f"{s.passed}/{s.runs}", failed, reaction, collided,
                      "-" if s.falls is None else str(s.falls)])
    return lines


def bar_chart(title: str, rates: list[Rate], path: Path, what: str) -> None:
    """Horizontal bars of rates with their Wilson intervals as whiskers (Pillow)."""
    from PIL import Image, ImageDraw

    left, bar_w, row_h, top = 230, 420, 26, 40
    img = Image.new("RGB", (left + bar_w + 150, top + row_h * len(rates) + 30), "white")
    d = ImageDraw.Draw(img)
    d.text((10, 10), title, fill="black")
    for i, r in enumerate(rates):
        y = top + i * row_h
        lo, hi = r.interval
        d.text((10, y + 6), r.label[:36], fill="black")
        d.rectangle([left, y + 4, left + bar_w, y + row_h - 4], outline=(200, 200, 200))
        d.rectangle([left, y + 4, left + int(bar_w * r.rate), y + row_h - 4],
                    fill=(200, 60, 60) if what == "failure" else (60, 150, 60))
        d.line([left + int(bar_w * lo), y + row_h // 2, left + int(bar_w * hi), y + row_h // 2], fill="black", width=2)
        for x in (lo, hi):
            d.line([left + int(bar_w * x), y + 7, left + int(bar_w * x), y + row_h - 7], fill="black", width=2)
        d.text((left + bar_w + 8, y + 6), f"{r.k}/{r.n} {100 * r.rate:.0f}%", fill="black")
    y = top + row_h * len(rates) + 8
    d.text((left, y), f"0        {what} rate, whiskers: Wilson 95% interval        1", fill=(90, 90, 90))
    img.save(path)


def _md_table(head: list[str], rows: list[list[Any]]) -> list[str]:
    """A markdown table; the first column left-aligned, the others right-aligned."""
    out = ["| " + " | ".join(head) + " |", "|---|" + "---:|" * (len(head) - 1)]
    return out + ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]


def write_report(results: Path) -> Path:
    """report.md, report.html and plots/*.png in the results folder; returns report.md's path."""
    rows = read_table(results)
    plots = results / "plots"
    plots.mkdir(exist_ok=True)
    passes = pass_rates(rows)
    bar_chart("pass rate per expectation", passes, plots / "pass_rates.png", "pass")
    by_param = failure_by_parameter(rows)
    for param, rates in by_param.items():
        bar_chart(f"failure rate per {param}", rates, plots / f"fail_{param}.png", "failure")
    spreads = metric_spread(rows)
    worst = _worst(results, rows)
    passed = sum(bool(r["passed"]) for r in rows)

    lines = [f"# Sweep report: {results}", "", f"{len(rows)} runs, {passed} passed.", "",
             "## Pass rate per expectation (Wilson 95 % interval)", ""]
    lines += _md_table(["expectation", "runs", "passed", "rate [95 % CI]"], [[r.label, r.n, r.k, r.text] for r in passes])
    lines += ["", "![pass rates](plots/pass_rates.png)", "", "## Per scenario", ""]
    lines += _md_table(SCENARIO_HEAD, scenario_cells(rows))
    lines += ["", "## Failure rate per parameter bin", ""]
    for param, rates in by_param.items():
        lines += [f"### {param}", ""]
        lines += _md_table(["bin", "runs", "failed", "failure rate [95 % CI]"], [[r.label, r.n, r.k, r.text] for r in rates])
        lines += ["", f"![failure rate per {param}](plots/fail_{param}.png)", ""]
    lines += ["## Metrics per scenario (min / median / max)", ""]
    lines += _md_table(["scenario", "metric", "runs", "spread"], [[s.scenario, s.metric, s.n, s.text] for s in spreads])
    lines += ["", "## Worst runs", ""]
    if not worst:
        lines.append("No run failed.")
    for w in worst:
        lines += [f"- {w.run_id} ({w.scenario}, seed {w.seed}{', ' + w.params if w.params else ''}): failed {w.failed}",
                  f"  `{w.replay}`" + (f" (run report: {w.report})" if w.report else "")]
    md = results / "report.md"
    with atomic_open(md) as fh:                     # a report is whole or absent, never half-written
        fh.write("\n".join(lines) + "\n")
    write_page(results / "report.html", "sweep_report.html.j2",
               {"results": results, "runs": len(rows), "passed": passed, "passes": passes,
                "pass_plot": data_uri(plots / "pass_rates.png"), "spreads": spreads, "worst": worst,
                "scenario_head": SCENARIO_HEAD, "scenario_cells": scenario_cells(rows),
                "params": [ParamRates(p, rates, data_uri(plots / f"fail_{p}.png")) for p, rates in by_param.items()]},
               extra_dirs=[TEMPLATES])
    return md
