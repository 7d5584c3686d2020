"""Benchmark: the model checker's search on 2 threads against 1 (issue 12, item 4); prints figures,
asserts nothing.

Model: id_retry on the first-level bus, 7 nodes (8.58 M states), the search alone: the bound and
liveness passes after it are the same one-thread code either way, and the model is compiled
(compile_model's Python, about 1.2 s of it, the same for any number of threads) once before the runs. One and two threads alternate,
`--repeat` times each, in this process, and the best wall time of each is compared: on a shared
machine the other load slows both alike only when they run at the same time, so the load average
is printed beside every run. Run: python bench/model_check_parallel_bench.py [--size N] [--repeat N]
"""
from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from model_check import spec_adapter  # noqa: E402
from model_check.checks import build_models  # noqa: E402
from model_check.compile import compile_model  # noqa: E402
from model_check.engine import explore  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--size", type=int, default=7, help="nodes on the first-level bus")
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--workers", type=int, default=2)
    args = ap.parse_args()
    (model,) = build_models("id_retry", spec_adapter.load(), bus="first", size=args.size)
    comp = compile_model(model)
    explore(model, comp, progress=False, use_native=True, check_liveness=False).release()   # C compiled, cached
    best: dict[int, tuple[float, float]] = {}
    counts = set()
    print(f"{model.name}: the search on 1 and {args.workers} threads, alternating")
    for _ in range(args.repeat):
        for w in (1, args.workers):
            t0 = time.perf_counter()
            res = explore(model, comp, progress=False, use_native=True, check_liveness=False, workers=w)
            wall, cpu = time.perf_counter() - t0, res.times["search"]
            counts.add((res.states, res.transitions, res.depth, res.ok))
            print(f"  {w} thread(s): {res.states:,} states, wall {wall:6.2f} s, search CPU {cpu:6.2f} s, "
                  f"peak +{res.peak_bytes / 2 ** 20:,.0f} MB, load average {os.getloadavg()[0]:.1f}", flush=True)
            res.release()
            old = best.get(w, (float("inf"), float("inf")))
            best[w] = (min(old[0], wall), min(old[1], cpu))
    (w1, c1), (w2, c2) = best[1], best[args.workers]
    print(f"best of {args.repeat}: 1 thread {w1:.2f} s wall / {c1:.2f} CPU s; {args.workers} threads {w2:.2f} s wall / "
          f"{c2:.2f} CPU s: speed-up {w1 / w2:.2f}x (wall), CPU {c2 / c1:.2f}x the one-thread search's; "
          f"{'counts agree' if len(counts) == 1 else 'COUNTS DIFFER'}")
    print(f"(on {os.cpu_count()} cores; the ideal is {min(args.workers, os.cpu_count() or 1)}x; the new states are "
          "put into the shared table after each round's expansion, and the rounds wait for their slowest thread; "
          "between rounds the threads rehash a grown table while the others wait)")


if __name__ == "__main__":
    main()
