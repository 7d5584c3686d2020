"""`arachnae sweep report RESULTS` (issue 14): how often a sweep's expectations hold, and what predicts failure.

Pass rate per expectation with a Wilson 95 % interval (sound at small counts and at 0 % / 100 %, where the
normal approximation collapses); failure rate per parameter bin; a table per base scenario (passes, which
expectation failed on which seeds, worst reaction, collisions, falls); the worst runs with their replay
command; PNG bar charts (Pillow, already a dependency) and report.md in the results folder.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

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


def worst_runs(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Failing runs, most expectations failed first (errors first of all), then by run id."""
    failing = [r for r in rows if not r["passed"]]
    return sorted(failing, key=lambda r: (r["error"] is None, -len((r["failed"] or "").split(", ")),
                                          r["run_id"]))[:WORST]


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


def scenario_table(rows: list[dict[str, Any]]) -> list[str]:
    """The per-scenario table as markdown lines."""
    lines = ["| scenario | passed | failed expectations (seeds) | worst reaction | collisions (runs, most contacts) "
             "| falls |", "|---|---:|---|---|---|---:|"]
    for s in per_scenario(rows):
        failed = "; ".join(f"{n} ({_seed_list(seeds)})" for n, seeds in s.failures.items()) or "-"
        reaction = f"{s.worst_reaction[0]:.2f} s (seed {s.worst_reaction[1]})" if s.worst_reaction else "-"
        collided = f"{s.collided[0]} runs, {s.collided[1]}" if s.collided and s.collided[0] else \
            ("0" if s.collided else "-")
        lines.append(f"| {s.scenario} | {s.passed}/{s.runs} | {failed} | {reaction} | {collided} | "
                     f"{'-' if s.falls is None else s.falls} |")
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


def _pct(r: Rate) -> str:
    lo, hi = r.interval
    return f"{100 * r.rate:.1f} % [{100 * lo:.1f}, {100 * hi:.1f}]"


def write_report(results: Path) -> Path:
    """report.md and plots/*.png in the results folder; returns report.md's path."""
    rows = read_table(results)
    plots = results / "plots"
    plots.mkdir(exist_ok=True)
    passes = pass_rates(rows)
    bar_chart("pass rate per expectation", passes, plots / "pass_rates.png", "pass")
    lines = [f"# Sweep report: {results}", "", f"{len(rows)} runs, {sum(bool(r['passed']) for r in rows)} passed.", "",
             "## Pass rate per expectation (Wilson 95 % interval)", "", "| expectation | runs | passed | rate [95 % CI] |",
             "|---|---:|---:|---|"]
    lines += [f"| {r.label} | {r.n} | {r.k} | {_pct(r)} |" for r in passes]
    lines += ["", "![pass rates](plots/pass_rates.png)", "", "## Per scenario", ""]
    lines += scenario_table(rows)
    lines += ["", "## Failure rate per parameter bin", ""]
    for param, rates in failure_by_parameter(rows).items():
        png = f"fail_{param}.png"
        bar_chart(f"failure rate per {param}", rates, plots / png, "failure")
        lines += [f"### {param}", "", "| bin | runs | failed | failure rate [95 % CI] |", "|---|---:|---:|---|"]
        lines += [f"| {r.label} | {r.n} | {r.k} | {_pct(r)} |" for r in rates]
        lines += ["", f"![failure rate per {param}](plots/{png})", ""]
    lines += ["## Worst runs", ""]
    worst = worst_runs(rows)
    if not worst:
        lines.append("No run failed.")
    for r in worst:
        params = ", ".join(f"{k.removeprefix('param.')}={v}" for k, v in r.items() if k.startswith("param."))
        lines += [f"- {r['run_id']} ({r['scenario']}, seed {r['seed']}{', ' + params if params else ''}): "
                  f"failed {r['error'] or r['failed']}", f"  `{r['replay']}`"]
    md = results / "report.md"
    md.write_text("\n".join(lines) + "\n")
    return md
