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

from arachnae_proto.enums import MovCmd  # noqa: E402
from behaviours.mmc import MMC  # noqa: E402
from behaviours.np3 import NP3, wrap_angle  # noqa: E402
from codegen.load import load_spec  # noqa: E402
from sim2d.cli import parse_seeds  # noqa: E402
from sim2d.metrics import check_expectations  # noqa: E402
from sim2d.scenario import load_scenario  # noqa: E402
from sim2d.sim import Simulation  # noqa: E402


_TURNS = (int(MovCmd.TURN_LEFT), int(MovCmd.TURN_RIGHT))


_SPILL_S = 1.0


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
    turns: dict[str, tuple[float, float, float]]   # "GAIT.CMD" -> true turn, the MMC's gait's, the NP3 copy's (deg)


class _Turns:
    """Turn grips, summed per gait and turn command over turn episodes (add):
    the body's true rotation against the MMC's own gait generator's (the model at grip 1, exact timing: it is the
    gait that drives the legs), and the NP3's copy (its grip taken out, map corrections left out) against the
    MMC's (what the copy misses: the MOVE's way to the MMC, stops the NP3 does not know of)."""

    def __init__(self, mmc: MMC) -> None:
        self.mmc_th = 0.0
        self.sums: dict[str, tuple[float, float, float]] = {}
        self.last: tuple[float, float, float] | None = None     # true, MMC's and NP3's heading at the last sample
        self.key = ""                                             # the turn episode running ("GAIT.CMD")
        self.ep = [0.0, 0.0, 0.0]                                 # ... its true, MMC's and NP3's turn so far (deg)
        self.turn_end = 0.0
        gait = mmc.gait
        step = gait.advance

        def advance(dt: float) -> None:
            step(dt)
            self.mmc_th += gait.moved.turn_rad
        gait.advance = advance                    # the measurement only: the MMC walks as before
        self.gait = gait

    def add(self, t: float, true_th: float, odo: object, fixed: float) -> None:
        """A turn episode runs from a turn command's start at the MMC to SPILL_S after it ended (the body follows
        the gait late), or to the next turn's start; map corrections of the NP3's heading are taken out. The
        angles add up sample by sample (a turn may pass half a circle)."""
        g = self.gait
        key = f"{MovCmd(g.gait).name}.{MovCmd(g.command).name}" if g.command in _TURNS else ""
        last, self.last = self.last, (true_th, self.mmc_th, odo.th - fixed)
        if self.key and ((key and key != self.key) or (not key and t - self.turn_end >= _SPILL_S)):
            a, b, c = self.sums.get(self.key, (0.0, 0.0, 0.0))
            self.sums[self.key] = (a + self.ep[0], b + self.ep[1], c + self.ep[2])
            self.key = ""
        if key and not self.key:
            self.key, self.ep = key, [0.0, 0.0, 0.0]
        elif self.key and last is not None:
            grip = odo.turn_grip
            self.ep[0] += math.degrees(wrap_angle(true_th - last[0]))
            self.ep[1] += math.degrees(self.mmc_th - last[1])
            self.ep[2] += math.degrees(wrap_angle(odo.th - fixed - last[2])) / grip
        if key:
            self.turn_end = t


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
        if self.turns is None:
            self.turns = _Turns(next(n for n in self.nodes.values() if isinstance(n, MMC)))
        self.turns.add(t, th, odo, np3.heading_fixed)


def measure(path: str, seed: int, spec: object) -> DrError:
    sc = load_scenario(path, spec).with_seed(seed)
    sim = _Measured(sc, spec)
    sim.dr_log = []
    sim.turns = None
    result = sim.run()
    log = sim.dr_log or [(0.0, 0.0, 0.0)]
    worst = max(log, key=lambda r: abs(r[1]))
    m = result.metrics
    fixed = m.get("nodes", {}).get("NP3", {}).get("map", {}).get("heading_fixed_deg", 0.0)
    failed = tuple(n for n, ok, _ in check_expectations(sc, m) if not ok)
    return DrError(sc.name, seed, log[-1][1], worst[1], worst[0], log[-1][2], fixed, m["collisions"], failed, sim.turns.sums if sim.turns else {})


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
            turns = " ".join(f"{k}:{a:.0f}/{b:.0f}/{c:.0f}" for k, (a, b, c) in sorted(r.turns.items()))
            print(line + f"  turns true/mmc/np3 {turns}", flush=True)
            if args.tsv:
                with open(args.tsv, "a") as f:
                    f.write("\t".join(str(v) for v in (r.scenario, r.seed, round(r.end_deg, 2), round(r.max_deg, 2),
                                                       round(r.max_at_s, 1), round(r.end_pos_m, 3), r.fixed_deg,
                                                       r.collisions, ",".join(r.failed) or "PASS",
                                                       repr(r.turns))) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
