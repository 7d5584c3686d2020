"""Cost of software in the loop (issue 15): a scenario run with the Python sensors, with each sensor
controller alone as AVR firmware in simavr, and with the whole sensor bus as firmware; wall times as a
ratio to the Python run measured in the same session, and each SIL node's RAM high-water mark.

    python bench/sil_bench.py [SCENARIO] [--nodes USRC,TPSC,...]

Needs `make firmware` (the role images and firmware/build/sil/sil_host). A benchmark, not a test: it never
fails on a figure; a scenario whose expectations fail is reported.
"""
from __future__ import annotations

import argparse
import resource
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from firmware.sil_bridge import ram_lines, ram_use, sil_names  # noqa: E402
from sim2d import runner  # noqa: E402

SENSOR_BUS = "USRC,TPSC,IRRC,ISC,TSC,LSC,PSC"


def cpu_s() -> float:
    """CPU seconds of this process and of its finished children (the simavr hosts): on 2 shared cores
    the comparable figure; wall time is printed too."""
    own, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime


def timed(path: str, spec, sil: tuple[str, ...] = ()):
    made: list = []
    t0, c0 = time.perf_counter(), cpu_s()
    out = runner.run_sil(path, sil, spec=spec, made=made) if sil else runner.run(path, spec=spec)
    ram = ram_use([n for n in made if n.host.proc.poll() is None])
    for n in made:
        n.host.close()                      # waits for the host: its CPU time is counted
    return out, time.perf_counter() - t0, cpu_s() - c0, ram


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("scenario", nargs="?", default=str(ROOT / "scenarios" / "fault_ir_unreliable.yaml"))
    ap.add_argument("--nodes", default=SENSOR_BUS, help="comma list of the nodes measured alone")
    args = ap.parse_args()
    spec = runner.load_spec_once()
    runs = [timed(args.scenario, spec) for _ in range(2)]        # the reference: the better of two
    py = runs[0][0]
    py_wall, py_cpu = min(r[1] for r in runs), min(r[2] for r in runs)
    sim_s = py.scenario.duration
    print(f"scenario {py.scenario.name}: {sim_s:.0f} s simulated; Python nodes only: {py_wall:.2f} s wall, "
          f"{py_cpu:.2f} s CPU ({'pass' if not py.failed else 'FAIL'})")
    print(f"{'SIL nodes':<24} {'wall s':>7} {'CPU s':>7} {'CPU x Python':>13} {'+CPU s/sim s':>13}  expectations")

    def row(label: str, sil: str) -> tuple[float, list]:
        out, wall, cpu, ram = timed(args.scenario, spec, (sil,))
        print(f"{label:<24} {wall:>7.2f} {cpu:>7.2f} {cpu / py_cpu:>13.2f} {(cpu - py_cpu) / sim_s:>13.3f}  "
              f"{'pass' if not out.failed else 'FAIL ' + ', '.join(n for n, _, _ in out.failed)}")
        return cpu, ram
    for name in sil_names([args.nodes]):
        row(name, name)
    cpu, ram = row("all seven", SENSOR_BUS)
    print(f"SIL cost per node (whole bus): {(cpu - py_cpu) / 7:.2f} CPU s for {sim_s:.0f} s simulated")
    print("RAM high-water in simavr, whole-bus run (bytes; static = .data + .bss, stack = RAMEND - lowest SP):")
    print("\n".join(ram_lines(ram)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
