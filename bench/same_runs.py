"""Same runs, faster? A simulator speed-up must leave every run's outputs byte-identical.

    python bench/same_runs.py --base REV [--seeds 1-2] [--keep DIR] [--base-runs DIR] SCENARIO...

Checks out REV (a commit, e.g. the branch point) into a temporary folder with `git archive`, runs
`arachnae sim batch SCENARIO... --seeds S -j 1` once with REV's code and once with this working tree's,
then compares every output file of every run byte for byte (trace.tsv, metrics.json, bus.pcapng, the
pictures, report.html, ...). Prints each tree's batch wall time and their ratio, measured in the same
call (the machine is shared: the ratio is the figure, not the seconds). `--base-runs DIR` reuses REV's
runs from an earlier call's `--keep` folder instead of running REV again (then no ratio).
Exit 1 when any file differs or is missing. A tool, not a test: it takes minutes.
"""
from __future__ import annotations

import argparse
import filecmp
import os
import subprocess
import sys
import tarfile
import tempfile
import time
from io import BytesIO
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def extract(rev: str, into: Path) -> Path:
    """The tree of `rev` as plain files (git archive), so both runs use the same .venv but their own code."""
    blob = subprocess.run(["git", "-C", str(ROOT), "archive", rev], check=True, capture_output=True).stdout
    with tarfile.open(fileobj=BytesIO(blob)) as tar:
        tar.extractall(into)
    return into


def batch(tree: Path, scenarios: list[str], seeds: str, out: Path) -> float:
    """Wall seconds of one `sim batch` with `tree`'s code (its outputs in `out`)."""
    env = dict(os.environ, PYTHONPATH=f"{tree}{os.pathsep}{tree / 'generated' / 'python'}")
    cmd = [sys.executable, "-m", "arachnae", "sim", "batch", *scenarios, "--seeds", seeds, "-j", "1", "--out", str(out)]
    t0 = time.perf_counter()
    done = subprocess.run(cmd, cwd=tree, env=env, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if done.returncode not in (0, 1):           # 1: an expectation failed, which both trees must agree on
        sys.exit(f"{tree}: sim batch exited {done.returncode}\n{done.stderr[-2000:]}")
    return wall


def differences(base: Path, head: Path) -> list[str]:
    """Files of the run folders under `base` and `head` that are missing on one side or differ."""
    out = [] if filecmp.cmp(base / "summary.md", head / "summary.md", shallow=False) else ["summary.md: differs"]
    for run in sorted(p.name for p in base.iterdir() if p.is_dir()):
        a, b = base / run, head / run
        if not b.is_dir():
            out.append(f"{run}: no run folder")
            continue
        names = {p.relative_to(a) for p in a.rglob("*") if p.is_file()} | {p.relative_to(b) for p in b.rglob("*") if p.is_file()}
        for name in sorted(names):
            pa, pb = a / name, b / name
            if not (pa.is_file() and pb.is_file()):
                out.append(f"{run}/{name}: only in {'base' if pa.is_file() else 'head'}")
            elif not filecmp.cmp(pa, pb, shallow=False):
                out.append(f"{run}/{name}: differs")
    return out


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("scenarios", nargs="+")
    ap.add_argument("--base", required=True, help="commit whose code is the reference")
    ap.add_argument("--seeds", default="1-2")
    ap.add_argument("--keep", help="keep both trees' runs in this folder (base/, head/)")
    ap.add_argument("--base-runs", help="REV's runs from an earlier --keep folder's base/ (not run again)")
    args = ap.parse_args()
    scenarios = [str(Path(s).resolve()) for s in args.scenarios]
    with tempfile.TemporaryDirectory(prefix="same-runs-") as tmp:
        keep = Path(args.keep) if args.keep else Path(tmp)
        head_out = keep / "head"
        if args.base_runs:
            base_out, base_wall = Path(args.base_runs), None
        else:
            base_out = keep / "base"
            base_wall = batch(extract(args.base, Path(tmp) / "tree"), scenarios, args.seeds, base_out)
        head_wall = batch(ROOT, scenarios, args.seeds, head_out)
        diff = differences(base_out, head_out)
    print(f"{len(scenarios)} scenarios, seeds {args.seeds}: head {head_wall:.1f} s"
          + (f", base {args.base} {base_wall:.1f} s, base/head {base_wall / head_wall:.2f}x" if base_wall else ""))
    print("\n".join(diff) if diff else "every output file of every run is byte-identical")
    return 1 if diff else 0


if __name__ == "__main__":
    raise SystemExit(main())
