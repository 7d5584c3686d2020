"""Cost of software in the loop (issue 15): a scenario run with the Python sensors, with each sensor
controller alone as AVR firmware in simavr, and with the whole sensor bus as firmware; wall times as a
ratio to the Python run measured in the same session, and each SIL node's RAM high-water mark.

    python bench/sil_bench.py [SCENARIO] [--nodes USRC,TPSC,...]

Needs `make firmware` (the role images and firmware/build/sil/sil_host). A benchmark, not a test: it never
fails on a figure; a scenario whose expectations fail is reported.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from firmware.sil_bridge import ram_lines, ram_use, run_scenario, sil_names  # noqa: E402
from sim2d import runner  # noqa: E402

SENSOR_BUS = "USRC,TPSC,IRRC,ISC,TSC,LSC,PSC"


def timed(path: str, spec, sil: tuple[str, ...] = ()):
    made: list = []
    t0 = time.perf_counter()
    out = run_scenario(path, sil, spec=spec, made=made) if sil else runner.run(path, spec=spec)
    wall = time.perf_counter() - t0
    ram = ram_use([n for n in made if n.host.proc.poll() is None])
    for n in made:
        n.host.close()
    return out, wall, ram


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("scenario", nargs="?", default=str(ROOT / "scenarios" / "fault_ir_unreliable.yaml"))
    ap.add_argument("--nodes", default=SENSOR_BUS, help="comma list of the nodes measured alone")
    args = ap.parse_args()
    spec = runner.load_spec_once()
    py, py_wall, _ = timed(args.scenario, spec)
    sim_s = py.scenario.duration
    print(f"scenario {py.scenario.name}: {sim_s:.0f} s simulated; Python nodes only: {py_wall:.2f} s wall "
          f"({'pass' if not py.failed else 'FAIL'})")
    print(f"{'SIL nodes':<32} {'wall s':>7} {'x Python':>9} {'+s per sim s':>13}  expectations")
    rams = {}
    for name in sil_names([args.nodes]):
        out, wall, ram = timed(args.scenario, spec, (name,))
        rams.update({r.node: r for r in ram})
        print(f"{name:<32} {wall:>7.2f} {wall / py_wall:>9.2f} {(wall - py_wall) / sim_s:>13.3f}  "
              f"{'pass' if not out.failed else 'FAIL ' + ', '.join(n for n, _, _ in out.failed)}")
    out, wall, ram = timed(args.scenario, spec, (SENSOR_BUS,))
    print(f"{'all seven (' + SENSOR_BUS + ')':<32} {wall:>7.2f} {wall / py_wall:>9.2f} {(wall - py_wall) / sim_s:>13.3f}  "
          f"{'pass' if not out.failed else 'FAIL ' + ', '.join(n for n, _, _ in out.failed)}")
    print(f"per SIL node (whole bus): {(wall - py_wall) / 7:.2f} s wall for {sim_s:.0f} s simulated")
    print("RAM high-water in simavr, whole-bus run (bytes; static = .data + .bss, stack = RAMEND - lowest SP):")
    print("\n".join(ram_lines(ram)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
