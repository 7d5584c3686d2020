"""Growth tables (issue 12): states, CPU seconds and memory per added node, ours beside SPIN.

Families: arbitration on the sensor bus (the issue-3 reference model: spec rule, collision
bound left out) with 2..7 slaves, and id_retry on the first-level bus with 3..N nodes.
Safety search only on both sides (SPIN -DSAFETY -DNOREDUCE, and again with -DCOLLAPSE),
so the state counts must agree. Each of our runs is a fresh process; its memory is the
resident peak it added (VmHWM - VmRSS at the start, see storage.Meter), SPIN's is pan's
"total actual memory usage". The fitted growth is exp(slope) of a least-squares line through
log(figure) against the node count. Prints figures, asserts only that state counts agree.
Run: python bench/model_check_growth_bench.py [--max-nodes 7] [--no-spin]   (7 is the default)
"""
from __future__ import annotations

import argparse
import math
import multiprocessing as mp
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from model_check import promela, spin, spec_adapter  # noqa: E402
from model_check.models import arbitration, id_retry  # noqa: E402


def build(family: str, n: int):
    spec = spec_adapter.load()
    if family == "arbitration":
        model = arbitration.build(spec_adapter.arbitration(spec, "sensor", "colliders"), "spec", n)
        model.invariants = [i for i in model.invariants if i.name != "collisions_bounded"]
    else:
        model = id_retry.build(spec_adapter.identification(spec, "first"), n)
    model.responses = []
    return model


def _ours(family: str, n: int, out) -> None:
    from model_check.compile import compile_model
    from model_check.engine import explore
    model = build(family, n)
    comp = compile_model(model)
    res = explore(model, comp, progress=False, use_native=True)
    # the search's CPU seconds: the C compile is apart, as pan's compile is apart from "pan s"
    out.put((res.states, res.times["search"], res.peak_bytes))


def ours(family: str, n: int) -> tuple[int, float, int]:
    ctx = mp.get_context("spawn")
    q = ctx.Queue()
    p = ctx.Process(target=_ours, args=(family, n, q))
    p.start()
    got = q.get()
    p.join()
    return got


def fit(ns: list[int], values: list[float]) -> float:
    pts = [(n, math.log(v)) for n, v in zip(ns, values) if v > 0]
    if len(pts) < 2:
        return float("nan")
    mx = sum(n for n, _ in pts) / len(pts)
    my = sum(y for _, y in pts) / len(pts)
    slope = sum((n - mx) * (y - my) for n, y in pts) / sum((n - mx) ** 2 for n, _ in pts)
    return math.exp(slope)


def table(family: str, ns: list[int], use_spin: bool) -> None:
    print(f"\n{family}: ours = our search in C (CPU s, compile apart), SPIN = pan -DSAFETY -DNOREDUCE [-DCOLLAPSE] (pan s)")
    head = f"{'n':>3}{'states':>12}{'ours s':>9}{'ours MB':>9}{'B/st':>7}"
    if use_spin:
        head += f"{'spin s':>9}{'spin MB':>9}{'coll s':>9}{'coll MB':>9}{'t/spin':>8}{'t/coll':>8}{'m/spin':>8}{'m/coll':>8}"
    print(head)
    rows = []
    for n in ns:
        states, secs, peak = ours(family, n)
        line = f"{n:>3}{states:>12,}{secs:>9.2f}{peak / 2**20:>9.1f}{peak / states:>7.0f}"
        row = {"n": n, "states": states, "secs": secs, "mb": peak / 2**20}
        if use_spin:
            text = promela.emit(build(family, n))
            kw = dict(depth_limit=max(100_000, 2 * states), hash_bits=max(18, states.bit_length() + 1))
            plain = spin.run(text, **kw)
            coll = spin.run(text, defines=("-DCOLLAPSE",), **kw)
            if not plain.stored == coll.stored == states:
                print(f"STATE COUNTS DIFFER: ours {states}, SPIN {plain.stored}, COLLAPSE {coll.stored}")
            line += (f"{plain.seconds:>9.2f}{plain.memory_mb:>9.1f}{coll.seconds:>9.2f}{coll.memory_mb:>9.1f}"
                     f"{secs / max(plain.seconds, 1e-3):>8.3f}{secs / max(coll.seconds, 1e-3):>8.3f}"
                     f"{row['mb'] / max(plain.memory_mb, 1e-3):>8.2f}{row['mb'] / max(coll.memory_mb, 1e-3):>8.2f}")
            row.update(spin_s=plain.seconds, spin_mb=plain.memory_mb, coll_s=coll.seconds, coll_mb=coll.memory_mb)
        print(line, flush=True)
        rows.append(row)
    keys = ["states", "secs", "mb"] + (["spin_s", "spin_mb", "coll_s", "coll_mb"] if use_spin else [])
    print("fitted growth per added node: " + ", ".join(
        f"{k} x{fit([r['n'] for r in rows], [r[k] for r in rows]):.2f}" for k in keys))


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--max-nodes", type=int, default=7, help="largest id_retry instance (7: 8.6 M states)")
    ap.add_argument("--no-spin", action="store_true")
    args = ap.parse_args()
    use_spin = not args.no_spin and spin.available()
    table("arbitration", list(range(2, 8)), use_spin)
    table("id_retry", list(range(3, args.max_nodes + 1)), use_spin)


if __name__ == "__main__":
    main()
