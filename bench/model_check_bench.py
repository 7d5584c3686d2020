"""Benchmark: our checker vs SPIN on the reference model (issue 3); prints figures, asserts nothing.

Reference model: arbitration on the sensor bus, 7 slaves, at most 2 collisions
per request tracked (spec arbitration.max_collisions_per_request), the spec's
backoff rule as declared. The collision-bound invariant is left out so both
tools explore the whole state space instead of stopping at its violation.
Run: python bench/model_check_bench.py [--slaves N]
"""
from __future__ import annotations

import argparse
import gc
import sys
import time
import tracemalloc
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from model_check import promela, spin, spec_adapter  # noqa: E402
from model_check.compile import compile_model  # noqa: E402
from model_check.bitstate import explore_bitstate  # noqa: E402
from model_check.engine import explore  # noqa: E402
from model_check.models import arbitration  # noqa: E402


def reference(slaves: int):
    spec = spec_adapter.load()
    model = arbitration.build(spec_adapter.arbitration(spec, "sensor", "colliders"), "spec", slaves)
    model.invariants = [i for i in model.invariants if i.name != "collisions_bounded"]
    model.responses = []
    return model


def bytes_per_state(model) -> float:
    """tracemalloc makes every allocation slow, so this runs on its own, after the timed run.

    tracemalloc also looks up the source line of every allocation, which is linear in the size of
    the function; the generated `expand` is large, so its line table is dropped here (it only
    serves tracebacks) to keep this run short. What is allocated is unchanged.
    """
    comp = compile_model(model)
    comp.expand.__code__ = comp.expand.__code__.replace(co_linetable=b"")
    gc.collect()
    tracemalloc.start()
    res = explore(model, comp, progress=False)
    current, _ = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    return current / res.states


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--slaves", type=int, default=7)
    args = ap.parse_args()
    model = reference(args.slaves)
    comp = compile_model(model)
    t0 = time.perf_counter()
    ours = explore(model, comp, progress=True)
    wall = time.perf_counter() - t0
    small = args.slaves - 1 if args.slaves > 5 else args.slaves   # tracemalloc run ~20x slower
    bps = bytes_per_state(reference(small))
    sp = spin.run(promela.emit(model), depth_limit=max(100_000, 2 * ours.states), hash_bits=max(18, ours.states.bit_length() + 1))
    print(f"reference model: {model.name}")
    print(f"{'':22}{'ours (numpy + C)':>18}{'SPIN (pan -DNOREDUCE)':>24}")
    print(f"{'states':22}{ours.states:>18,}{sp.stored:>24,}")
    print(f"{'transitions':22}{ours.transitions:>18,}{sp.transitions:>24,}")
    print(f"{'search time (s)':22}{wall:>18.2f}{sp.seconds:>24.2f}")
    print(f"{'states/s':22}{ours.states / wall:>18,.0f}{sp.stored / max(sp.seconds, 1e-9):>24,.0f}")
    print(f"{'bytes/state':22}{bps:>18.1f}{sp.memory_mb * 2 ** 20 / max(sp.stored, 1):>24.1f}")
    print(f"ratio ours/SPIN wall time: {wall / max(sp.seconds, 1e-9):.1f}x (target <= 4x); "
          f"target >= 250,000 states/s: {'met' if ours.states / wall >= 250_000 else 'not met'}")
    print(f"(our bytes/state measured with tracemalloc on the {small}-slave instance; SPIN's from pan's "
          f"'total actual memory usage', which includes its hash table and stack)")
    print("states agree" if sp.stored == ours.states else "STATE COUNTS DIFFER")
    # issue 12, item 4: the same search on two threads, timed against the one-thread run above
    # (bench/model_check_parallel_bench.py: id_retry, alternating runs)
    t0 = time.perf_counter()
    par = explore(model, comp, progress=False, workers=2)
    pwall = time.perf_counter() - t0
    print(f"parallel search, 2 threads: {par.states:,} states, wall {pwall:.2f} s = {wall / max(pwall, 1e-9):.2f}x "
          f"the one-thread search ({par.cpu:.2f} CPU s in all); "
          f"{'counts agree' if (par.states, par.transitions) == (ours.states, ours.transitions) else 'COUNTS DIFFER'}")
    # issue 12, item 5: bitstate search with a table of about 8 bits per state
    bits = max(12, (8 * ours.states).bit_length())
    bs, est = explore_bitstate(model, bits, comp, progress=False)
    print(f"bitstate 2^{bits} bits: {bs.states:,} of {ours.states:,} states ({100 * bs.states / ours.states:.3f} %), "
          f"estimated coverage {100 * est.coverage:.3f} %, {bs.cpu:.2f} CPU s")


if __name__ == "__main__":
    main()
