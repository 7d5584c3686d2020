"""Fault sweeps (issue 14): a real Dask LocalCluster, resume after an interruption, file:line errors."""
from __future__ import annotations

import json
import shutil
from pathlib import Path

import pyarrow.parquet as pq
import pytest

from arachnae.cli import main
from arachnae.errors import UserError
from sim2d import sweep as sw
from sim2d.sweep_report import scenario_cells, wilson, write_report

TINY = """\
name: tiny
duration: 6
arena: {size: [4.0, 4.0]}
robot: {pose: [1.0, 2.0, 0]}
expect:
  no_collision: true
  min_distance: 0.05
"""
# 4 runs: killing the MMC at 0.5 s stops the robot (min_distance fails); losing one leg does not
SWEEP = """\
scenarios: [tiny.yaml]
seeds: [1, 2]
grid:
  fault_node: [MMC, "LCP(3)"]
  fault_at: [0.5]
metrics: [distance_walked_m, collisions, post.verdict, final_pose]
"""


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    d = tmp_path_factory.mktemp("sweep")
    (d / "tiny.yaml").write_text(TINY)
    (d / "sweep.yaml").write_text(SWEEP)
    return d


def _table(out: Path) -> list[dict]:
    """The table without the replay column (it names the results folder, which differs between the two runs)."""
    return [{k: v for k, v in r.items() if k != "replay"} for r in pq.read_table(out / "results.parquet").to_pylist()]


@pytest.fixture(scope="module")
def two_workers(folder: Path, spec) -> Path:
    s = sw.load_sweep(folder / "sweep.yaml", spec)
    res = sw.execute(s, spec, folder / "two", workers=2, progress=False)
    assert (res.runs, res.ran) == (4, 4)
    assert res.dashboard and res.dashboard.startswith("http://")      # issue 14: the dashboard link is given
    return folder / "two"


def test_a_local_cluster_serves_the_dask_dashboard() -> None:
    """The link printed with the progress bar is a live page while the sweep runs (bokeh is a dependency)."""
    from urllib.request import urlopen

    client = sw.client_for(None, 1)
    try:
        with urlopen(client.dashboard_link, timeout=30) as page:
            assert page.status == 200 and b"Dask" in page.read()
    finally:
        cluster = client.cluster
        client.close()
        cluster.close()


def test_two_workers_table_and_failed_folders(two_workers: Path) -> None:
    rows = _table(two_workers)
    assert [r["run_id"] for r in rows] == ["r000000", "r000001", "r000002", "r000003"]
    by_node = {r["param.fault_node"]: r for r in rows if r["seed"] == 1}
    assert by_node["MMC"]["passed"] is False and by_node["MMC"]["expect.min_distance"] is False
    assert by_node["MMC"]["metric.distance_walked_m"] < 0.05
    assert by_node["LCP(3)"]["passed"] is True and by_node["LCP(3)"]["metric.distance_walked_m"] > 0.05
    assert all(len(r["trace_hash"]) == 64 for r in rows)
    failed = {p.name for p in (two_workers / "failed").iterdir()}
    assert failed == {r["run_id"] for r in rows if not r["passed"]}       # failing runs only
    assert (two_workers / "failed" / "r000000" / "metrics.json").is_file()
    # the effective scenario is a real scenario file: it carries the override
    text = (two_workers / "scenarios" / "r000000.yaml").read_text()
    assert "kill: MMC" in text and "seed: 1" in text


def test_one_worker_interrupted_then_resumed_gives_the_same_table(folder: Path, two_workers: Path, spec) -> None:
    s = sw.load_sweep(folder / "sweep.yaml", spec)
    out = folder / "one"
    first = sw.execute(s, spec, out, workers=1, stop_after=1, progress=False)
    assert first.ran == 1 and not (out / "results.parquet").exists()
    before = sorted(p.name for p in (out / "rows").glob("*.json"))
    assert len(before) == 1
    (out / "rows" / "r000003.json").write_text('{"run_id": "r0000')   # a row cut off as the sweep was killed
    second = sw.execute(s, spec, out, workers=1, progress=False)
    assert second.ran == 3                                            # no run lost, none run twice
    assert sorted(p.name for p in (out / "rows").glob("*.json")) == [f"r00000{i}.json" for i in range(4)]
    assert _table(out) == _table(two_workers)
    again = sw.execute(s, spec, out, workers=1, progress=False)      # finished: nothing runs, no cluster
    assert again.ran == 0 and _table(out) == _table(two_workers)


def test_report(two_workers: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["sweep", "report", str(two_workers)]) == 0
    md = (two_workers / "report.md").read_text()
    assert "| min_distance | 4 | 2 | 50.0 % [15.0, 85.0] |" in md
    assert "| MMC | 2 | 2 | 100.0 % [34.2, 100.0] |" in md and "| LCP(3) | 2 | 0 | 0.0 % [0.0, 65.8] |" in md
    assert f"arachnae sim run {two_workers / 'scenarios' / 'r000000.yaml'} --seed 1" in md
    # per scenario: the MMC kill fails min_distance on both seeds; reaction and falls were not collected
    assert "| tiny | 2/4 | min_distance (1, 2) | - | 0 | - |" in md
    for png in ("pass_rates.png", "fail_fault_node.png"):
        assert (two_workers / "plots" / png).read_bytes().startswith(b"\x89PNG")
    # the spread a builder sets expectations from: every run gave a distance, and a verdict word is counted
    rows = {r["run_id"]: r for r in pq.read_table(two_workers / "results.parquet").to_pylist()}
    walked = sorted(r["metric.distance_walked_m"] for r in rows.values())
    spread = f"{round(walked[0], 3):g} / {round((walked[1] + walked[2]) / 2, 3):g} / {round(walked[-1], 3):g}"
    assert f"| tiny.yaml | distance_walked_m | 4 | {spread} |" in md, md
    assert "| tiny.yaml | post.verdict | 4 | OPERATIONAL 4 |" in md


def test_report_page_links_each_failing_run_to_its_own_report(two_workers: Path) -> None:
    """report.html (issue 14 item 3, with the run reports of issue 13): the plots inline, the worst runs linked."""
    assert main(["sweep", "report", str(two_workers)]) == 0
    page = (two_workers / "report.html").read_text()
    charts = sorted(p.name for p in (two_workers / "plots").glob("*.png"))
    assert charts == ["fail_fault_at.png", "fail_fault_node.png", "fail_scenario.png", "pass_rates.png"]
    assert '<meta name="generator" content="arachnae">' in page and page.count("data:image/png;base64,") == len(charts)
    failing = [r["run_id"] for r in pq.read_table(two_workers / "results.parquet").to_pylist() if not r["passed"]]
    assert failing
    for run_id in failing:
        assert f'<a href="failed/{run_id}/report.html">{run_id}</a>' in page
        assert (two_workers / "failed" / run_id / "report.html").is_file()
    assert "<td>tiny</td><td>2/4</td><td>min_distance (1, 2)</td>" in page        # the per-scenario table


def test_scenario_table_gives_worst_reaction_collisions_and_falls() -> None:
    """The note's pass table from a suite sweep's columns (no cluster: rows as read_table gives them)."""
    def row(scenario: str, seed: int, reaction: float | None, contacts: int, fell: bool, ok: bool) -> dict:
        return {"scenario": scenario, "seed": seed, "metric.max_reaction_s": reaction, "metric.collisions": contacts,
                "metric.fell": fell, "expect.no_collision": contacts == 0, "expect.max_reaction": ok,
                "passed": ok and contacts == 0, "error": None}
    rows = [row("../course.yaml", 1, 0.4, 0, False, True), row("../course.yaml", 2, 1.3, 22, True, False),
            row("../course.yaml", 3, None, 3, False, True), row("../open/ring.yaml", 1, None, 0, False, True)]
    cells = scenario_cells(rows)
    assert cells[0] == ["course", "1/3", "no_collision (2, 3); max_reaction (2)", "1.30 s (seed 2)", "2 runs, 22", "1"]
    assert cells[1] == ["ring", "1/1", "-", "-", "0", "0"]


def test_wilson_known_values() -> None:
    lo, hi = wilson(5, 10)
    assert (round(lo, 4), round(hi, 4)) == (0.2366, 0.7634)
    assert wilson(0, 0) == (0.0, 1.0)
    assert wilson(0, 20)[0] == 0.0 and wilson(20, 20)[1] == 1.0


def test_a_results_folder_of_another_sweep_is_refused(folder: Path, two_workers: Path, spec) -> None:
    (folder / "other.yaml").write_text(SWEEP.replace("seeds: [1, 2]", "seeds: [3, 4]"))
    s = sw.load_sweep(folder / "other.yaml", spec)
    with pytest.raises(UserError, match="different sweep"):
        sw.execute(s, spec, two_workers, workers=1, progress=False)
    keep = folder / "mine"
    keep.mkdir()
    (keep / "notes.txt").write_text("mine")
    with pytest.raises(UserError, match="not a sweep's results folder"):
        sw.execute(s, spec, keep, workers=1, progress=False)
    assert (keep / "notes.txt").read_text() == "mine" and len(list(keep.iterdir())) == 1


BAD = [
    ("scenarios: [tiny.yaml]\nmetrics: [collisions]\ngird: {}\n", 3, "unknown key 'gird'"),
    ("scenarios: [tiny.yaml]\nmetrics: [collisions]\ngrid:\n  fault_at: [1]\n", 4, "fault_at needs fault_node"),
    ("scenarios: [tiny.yaml]\nmetrics: [collisions]\ngrid:\n  fault_node: [XYZ]\n  fault_at: [1]\n", 4,
     "'XYZ' is not one of"),
    ("scenarios: [tiny.yaml]\nmetrics: [collisions]\ngrid:\n  fault_node: [MMC]\n  fault_at: [1, 9]\n", 4,
     "run r000001 (tiny.yaml, seed 1, fault_node=MMC, fault_at=9): the scenario it makes is refused: faults[0].at"),
    ("scenarios: [tiny.yaml]\nmetrics:\n  - collisions\n  - nodes.MMC.legs\n  - no.such\n", 5, "metrics[2]: 'no.such'"),
    ("scenarios: [tiny.yaml]\nmetrics: [collisions]\nsample:\n  count: 3\n  ranges:\n    bus: {choice: [sensor]}\n"
     "    bus_loss: {min: 0.5, max: 0.1}\n", 7, "min 0.5 is above max 0.1"),
    ("scenarios:\n  - tiny.yaml\n  - gone.yaml\nmetrics: [collisions]\n", 3, "no such scenario file 'gone.yaml'"),
    ("scenarios: [tiny.yaml]\nseeds: {from: 5, to: 2}\nmetrics: [collisions]\n", 2, "from 5 is above to 2"),
    ("scenarios: [tiny.yaml]\nseeds: [1, 2.0]\nmetrics: [collisions]\n", 2, "expected a list of seeds"),
]


@pytest.mark.parametrize("text,line,message", BAD)
def test_bad_sweep_file_is_one_line_with_file_and_line(folder: Path, text: str, line: int, message: str,
                                                      capsys: pytest.CaptureFixture[str]) -> None:
    bad = folder / "bad.yaml"
    bad.write_text(text)
    out = folder / "bad-out"
    assert main(["sim", "sweep", str(bad), "--out", str(out), "--workers", "1"]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith(f"{bad}:{line}: "), err
    assert message in err
    assert not out.exists()                  # nothing half-written


def test_a_killed_worker_loses_no_run_and_duplicates_none(folder: Path, two_workers: Path, spec) -> None:
    """Issue 14.4: a worker process dies (SIGKILL) while the sweep runs on a real 2-worker cluster: Dask runs its
    task again elsewhere, and the table holds every run once, equal to the undisturbed sweep's."""
    import os
    import signal
    import threading
    import time

    from distributed import Client, LocalCluster

    s = sw.load_sweep(folder / "sweep.yaml", spec)
    out = folder / "killed"
    cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None)
    try:
        client = Client(cluster)
        pids = client.run(os.getpid)                 # worker address -> its process
        result: dict[str, sw.SweepResult] = {}
        runner = threading.Thread(target=lambda: result.update(r=sw.execute(s, spec, out, scheduler=cluster.scheduler_address,
                                                                            progress=False)))
        runner.start()
        deadline = time.monotonic() + 300
        while not list((out / "rows").glob("*.json")) if (out / "rows").exists() else True:
            assert time.monotonic() < deadline and runner.is_alive(), "no run finished"
            time.sleep(0.05)
        victim = sorted(pids.values())[0]
        os.kill(victim, signal.SIGKILL)              # mid-sweep
        finished_at_kill = len(list((out / "rows").glob("*.json")))
        runner.join(timeout=600)
        assert not runner.is_alive()
        client.close()
    finally:
        cluster.close()
    res = result["r"]
    assert finished_at_kill < 4 and (res.runs, res.ran) == (4, 4)
    rows = [json.loads(p.read_text())["run_id"] for p in sorted((out / "rows").glob("*.json"))]
    assert rows == ["r000000", "r000001", "r000002", "r000003"]
    assert _table(out) == _table(two_workers)


def test_the_suite_sweep_lists_every_scenario(spec) -> None:
    """make sweep-suite (issue 14): every scenario of scenarios/ and scenarios/open/, not the 60 s benchmark
    (fault_us_killed_explore was missing from the seeds 1-20 sweep on ec5018d)."""
    root = Path(__file__).resolve().parents[2] / "scenarios"
    s = sw.load_sweep(root / "sweeps" / "suite.yaml", spec)
    listed = {r.base_path for r in s.runs}
    expected = {p.resolve() for p in [*root.glob("*.yaml"), *(root / "open").glob("*.yaml")] if p.name != "bench_60s.yaml"}
    assert listed == expected
