from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from PIL import Image

ROOT = Path(__file__).resolve().parents[2]


def cli(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "arachnae", "sim", *args], capture_output=True, text=True,
                          cwd=cwd or ROOT, timeout=300)


def test_run_writes_outputs_and_passes(tmp_path):
    out = tmp_path / "o"
    p = cli("run", str(ROOT / "scenarios" / "post_halted.yaml"), "--out", str(out), "--gif")
    assert p.returncode == 0, p.stderr
    assert "trace hash" in p.stdout and "PASS post" in p.stdout
    m = json.loads((out / "metrics.json").read_text())
    assert m["post"]["verdict"] == "HALTED" and all(e["passed"] for e in m["expectations"])
    lines = (out / "trace.tsv").read_text().splitlines()
    assert lines[0].startswith("start_s\tend_s\tbus\tsender\tsrc\tdst\tmessage") and len(lines) > 10
    assert Image.open(out / "run.png").size[0] > 100
    assert Image.open(out / "run.gif").n_frames > 5


def test_failed_expectation_exits_nonzero_naming_it(tmp_path, write):
    s = write("s.yaml", "duration: 3\narena: {size: [4, 3]}\nrobot: {pose: [1, 1, 0]}\nexpect: {post: HALTED, no_collision: true}\n")
    p = cli("run", str(s), "--out", str(tmp_path / "o"))
    assert p.returncode == 1
    assert p.stderr.strip().endswith("expectation failed: post") and "Traceback" not in p.stderr


def test_bad_scenario_is_one_line_and_writes_nothing(tmp_path, write):
    s = write("s.yaml", "duration: 3\narena: {size: [4, 3]}\nrobot: {pose: [1, 1, 0], absent: [XYZ]}\n")
    out = tmp_path / "o"
    p = cli("run", str(s), "--out", str(out))
    assert p.returncode == 1 and p.stderr.count("\n") == 1
    assert p.stderr.startswith(f"{s}:3: robot.absent[0]: 'XYZ' is not one of")
    assert not out.exists() and list(tmp_path.glob(".o.*")) == []
    p = cli("run", str(tmp_path / "missing.yaml"))
    assert p.returncode == 1 and "no such scenario file" in p.stderr


def test_batch_runs_scenarios_times_seeds(tmp_path, write):
    a = write("a.yaml", "name: a\nduration: 2\narena: {size: [4, 3]}\nrobot: {pose: [1, 1, 0]}\nexpect: {post: OPERATIONAL}\n")
    b = write("b.yaml", "name: b\nduration: 2\narena: {size: [4, 3]}\nrobot: {pose: [1, 1, 0]}\nexpect: {never_moves: true, post: HALTED}\n")
    p = cli("batch", str(a), str(b), "--seeds", "1-2", "-j", "2", "--out", str(tmp_path / "runs"), "--outputs", "failed")
    assert p.returncode == 1                      # b fails: POST is OPERATIONAL
    assert "2 passed, 2 failed" in p.stdout
    assert sorted(d.name for d in (tmp_path / "runs").iterdir()) == [".arachnae-batch", "a-seed1", "a-seed2",
                                                                     "b-seed1", "b-seed2", "summary.md"]
    # --outputs failed: a passing run keeps its trace and metrics, a failing one everything (report.html, ...)
    assert sorted(f.name for f in (tmp_path / "runs" / "a-seed1").iterdir()) == [".arachnae-run", "metrics.json",
                                                                                 "trace.tsv"]
    assert {"report.html", "bus.pcapng", "run.png"} <= {f.name for f in (tmp_path / "runs" / "b-seed1").iterdir()}
    rows = (tmp_path / "runs" / "summary.md").read_text().splitlines()[2:]   # one row per run, failures marked
    assert [r.split(" | ")[:3] for r in rows] == [["| a", "1", "PASS"], ["| a", "2", "PASS"],
                                                  ["| b", "1", "FAIL"], ["| b", "2", "FAIL"]]
    p = cli("batch", str(a), "--seeds", "x")
    assert p.returncode == 1 and p.stderr.startswith("--seeds:")


def test_same_seed_prints_the_same_hash_and_metrics_cover_issue_4(tmp_path):
    from arachnae_proto.frame import parse

    runs = [cli("run", str(ROOT / "scenarios" / "frame_loss.yaml"), "--seed", "4", "--out", str(tmp_path / d))
            for d in ("a", "b")]
    hashes = [next(ln for ln in p.stdout.splitlines() if ln.startswith("trace hash")) for p in runs]
    assert runs[0].returncode == 0 and hashes[0] == hashes[1] and len(hashes[0]) == len("trace hash ") + 64
    assert (tmp_path / "a" / "trace.tsv").read_bytes() == (tmp_path / "b" / "trace.tsv").read_bytes()
    m = json.loads((tmp_path / "a" / "metrics.json").read_text())
    for key in ("post", "distance_walked_m", "collisions", "min_clearance_m", "pit_events", "tilt_events",
                "bus_layers", "frame_loss", "reaction_latencies_s", "trace_hash"):
        assert key in m, key
    assert m["post"]["verdict"] == "OPERATIONAL" and m["frame_loss"] > 0
    assert set(m["bus_layers"]) == {"0", "1", "2"} and m["bus_layers"]["2"]["buses"] == [f"joints{i}" for i in range(1, 7)]
    assert 0 < m["bus_layers"]["1"]["load_max"] < 1
    # the trace's message column is the generated codec's reading of its bytes column
    for line in (tmp_path / "a" / "trace.tsv").read_text().splitlines()[1:]:
        cols = line.split("\t")
        if cols[2] == "debug":            # a debug-port row (tracecheck.trace): no bytes
            assert cols[6].startswith("post_verdict verdict=")
            continue
        if not cols[6].startswith("<"):
            assert parse(bytes.fromhex(cols[7])).message.describe() == cols[6]
