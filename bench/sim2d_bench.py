"""Real-time factor of sim2d (issue 4: >= 50x for one robot, the full 39-node network,
every bus at its spec baud rate, the ultrasonic head scanning).

    python bench/sim2d_bench.py [SCENARIO] [--repeat N]

Times Simulation.run() only (the spec is loaded once before, output files are
not written); prints the best of N runs. A benchmark, not a test: it never fails.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from codegen.load import load_spec  # noqa: E402
from sim2d.scenario import load_scenario  # noqa: E402
from sim2d.sim import Simulation  # noqa: E402


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("scenario", nargs="?", default=str(ROOT / "scenarios" / "bench_60s.yaml"))
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    spec = load_spec()
    sc = load_scenario(args.scenario, spec)
    best = float("inf")
    for _ in range(args.repeat):
        t0 = time.perf_counter()
        sim = Simulation(sc, spec)
        result = sim.run()
        best = min(best, time.perf_counter() - t0)
    m = result.metrics
    scans = len(sim.sensors.log.sonar)
    print(f"scenario {sc.name}: {sc.duration:.0f} s simulated, {len(sim.nodes)} nodes, {len(sim.buses)} buses, "
          f"{m['frames']} frames, {scans} sonar echoes")
    print(f"wall {best:.3f} s (best of {args.repeat}) -> real-time factor {sc.duration / best:.1f}x (target >= 50x)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
