"""How far the NP3's dead-reckoned pose is off the simulated body's (issue 17: the heading for every task).

    python bench/dr_heading.py SCENARIO... [--seeds 1-5] [--tsv FILE]

Runs each scenario on each seed (Simulation.run, no output folder) and samples, at the simulator's pose log
rate, the NP3's dead-reckoned pose (its start frame turned onto the start pose) against the body's true pose.
Prints per run: the heading error at the end and its maximum over the run, the position error at the end, the
heading corrections the map made, and whether the scenario's expectations held. A measurement, not a test: the
simulator's ground truth is read here only, never by the behaviours.
"""
from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from typing import NamedTuple

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from behaviours.np3 import NP3, wrap_angle  # noqa: E402
from codegen.load import load_spec  # noqa: E402
from sim2d.cli import parse_seeds  # noqa: E402
from sim2d.metrics import check_expectations  # noqa: E402
from sim2d.scenario import load_scenario  # noqa: E402
from sim2d.sim import Simulation  # noqa: E402


class DrError(NamedTuple):
    """One run's dead-reckoning figures (degrees, metres)."""
    scenario: str
    seed: int
    end_deg: float
    max_deg: float
    max_at_s: float
    end_pos_m: float
    fixed_deg: float
    collisions: int
    failed: tuple[str, ...]


class _Measured(Simulation):
    """A Simulation that also logs the NP3's dead-reckoned pose beside the true one."""

    def _sample(self, t: float) -> None:
        super()._sample(t)
        np3 = next(n for n in self.nodes.values() if isinstance(n, NP3))
        odo = getattr(np3, "odo", None)
        if odo is None:
            return
        x0, y0, th0 = self.scenario.start
        c, s = math.cos(th0), math.sin(th0)
        x, y, th = self.robot.pose
        bx, by = x0 + odo.x * c - odo.y * s, y0 + odo.x * s + odo.y * c
        self.dr_log.append((t, math.degrees(wrap_angle(odo.th + th0 - th)), math.hypot(bx - x, by - y)))


def measure(path: str, seed: int, spec: object) -> DrError:
    sc = load_scenario(path, spec).with_seed(seed)
    sim = _Measured(sc, spec)
    sim.dr_log = []
    result = sim.run()
    log = sim.dr_log or [(0.0, 0.0, 0.0)]
    worst = max(log, key=lambda r: abs(r[1]))
    m = result.metrics
    fixed = m.get("nodes", {}).get("NP3", {}).get("map", {}).get("heading_fixed_deg", 0.0)
    failed = tuple(n for n, ok, _ in check_expectations(sc, m) if not ok)
    return DrError(sc.name, seed, log[-1][1], worst[1], worst[0], log[-1][2], fixed, m["collisions"], failed)


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("scenarios", nargs="+")
    ap.add_argument("--seeds", default="1-5")
    ap.add_argument("--tsv", help="append one row per run to this file")
    args = ap.parse_args()
    spec = load_spec()
    print(f"{'scenario':24} {'seed':>4} {'end_deg':>8} {'max_deg':>8} {'at_s':>6} {'end_m':>6} {'fixed':>7} "
          f"{'coll':>4} result")
    for path in args.scenarios:
        for seed in parse_seeds(args.seeds):
            r = measure(path, seed, spec)
            line = (f"{r.scenario:24} {r.seed:>4} {r.end_deg:8.1f} {r.max_deg:8.1f} {r.max_at_s:6.1f} "
                    f"{r.end_pos_m:6.2f} {r.fixed_deg:7.1f} {r.collisions:>4} "
                    + ("PASS" if not r.failed else "FAIL " + ",".join(r.failed)))
            print(line, flush=True)
            if args.tsv:
                with open(args.tsv, "a") as f:
                    f.write("\t".join(str(v) for v in (r.scenario, r.seed, round(r.end_deg, 2), round(r.max_deg, 2),
                                                       round(r.max_at_s, 1), round(r.end_pos_m, 3), r.fixed_deg,
                                                       r.collisions, ",".join(r.failed) or "PASS")) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
