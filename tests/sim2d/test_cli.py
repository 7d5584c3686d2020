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
    p = cli("batch", str(a), str(b), "--seeds", "1-2", "-j", "2", "--out", str(tmp_path / "runs"))
    assert p.returncode == 1                      # b fails: POST is OPERATIONAL
    assert "2 passed, 2 failed" in p.stdout
    assert sorted(d.name for d in (tmp_path / "runs").iterdir()) == ["a-seed1", "a-seed2", "b-seed1", "b-seed2"]
    p = cli("batch", str(a), "--seeds", "x")
    assert p.returncode == 1 and p.stderr.startswith("--seeds:")
