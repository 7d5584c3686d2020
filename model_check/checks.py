"""Build the named models from the spec, run them, and report in text or JSON."""
from __future__ import annotations

import json
from typing import Any

from arachnae.errors import UserError
from model_check import msc, replay, spec_adapter
from model_check.engine import Result, explore
from model_check.gcl import Model
from model_check.models import arbitration, id_retry, post, reaction

MODELS = ("arbitration", "id_retry", "post", "reaction")


def build_models(name: str, spec, variant: str = "spec", bus: str | None = None, size: int | None = None,
                 legs: int | None = None, symmetry: bool = True, scope: str | None = None) -> list[Model]:
    """The models `arachnae check NAME` runs; `all` is what `make check` proves."""
    if name == "all":
        return (build_models("arbitration", spec, variant, None, size, scope=scope)
                + build_models("id_retry", spec, bus=None, size=size)
                + build_models("post", spec, legs=legs, symmetry=symmetry)
                + build_models("reaction", spec, size=size))
    if name == "arbitration":
        buses = [bus] if bus else spec_adapter.contended_buses(spec)
        return [arbitration.build(spec_adapter.arbitration(spec, b, scope), variant, size) for b in buses]
    if name == "id_retry":
        buses = [bus] if bus else spec_adapter.contended_buses(spec)
        return [id_retry.build(spec_adapter.identification(spec, b), size) for b in buses]
    if name == "post":
        return [post.build(spec_adapter.post(spec), legs, symmetry)]
    if name == "reaction":
        return [reaction.build(spec_adapter.reaction(spec), others=size)]
    raise UserError(f"unknown model {name!r}; choose one of {', '.join(MODELS + ('all',))}")


def deadline(res: Result) -> tuple[float, float, str] | None:
    """(worst ms, bound ms, seed section) for a model whose response has a bound in the spec (reaction, 5.2)."""
    m = res.model
    bound = getattr(m, "bound_ms", None)
    worst = [b for b in res.bounds.values() if isinstance(b, int)]
    if bound is None or not worst or len(worst) != len(m.responses):
        return None
    return max(worst) * m.tick_us / 1000, bound, getattr(m, "bound_section", "")


def meets_deadline(res: Result) -> bool:
    d = deadline(res)
    return d is None or d[0] <= d[1]


def ms(ticks: int | None, tick_us: float) -> str:
    return "unbounded" if ticks is None else f"{ticks} ticks = {ticks * tick_us / 1000:.1f} ms"


def summary(res: Result) -> dict[str, Any]:
    m = res.model
    out: dict[str, Any] = {
        "model": m.name, "holds": res.ok, "proof": res.proof, "states": res.states, "transitions": res.transitions,
        "depth": res.depth, "seconds": round(res.seconds, 3), "states_per_cpu_s": round(res.rate),
        "bytes_per_state": round(res.bytes_per_state, 1),
        "store_bytes_per_state": round(res.store_bytes_per_state, 1), "cpu_seconds": round(res.cpu, 3),
        "peak_mb": round(res.peak_bytes / 2 ** 20, 1), "times": {k: round(v, 3) for k, v in res.times.items()},
        "tick_us": m.tick_us, "invariants": [i.name for i in m.invariants],
        "responses": {r.name: res.bounds.get(r.name, "not checked") for r in m.responses},
        "never_fired": res.never_fired, "warnings": res.warnings, "notes": m.notes,
    }
    finite = [b for b in res.bounds.values() if isinstance(b, int)]
    if finite and len(finite) == len(m.responses):
        out["bound_ticks"] = max(finite)
        out["bound_ms"] = round(max(finite) * m.tick_us / 1000, 3)
    d = deadline(res)
    if d is not None:
        out["deadline"] = {"worst_ms": round(d[0], 3), "bound_ms": d[1], "section": d[2], "meets": d[0] <= d[1]}
    if res.violation:
        v = res.violation
        out["counterexample"] = msc.to_json(res, v)
        out["mermaid"] = msc.to_mermaid(res, v)
    return out


def text(res: Result) -> str:
    m, s = res.model, summary(res)
    lines = [f"model {m.name}",
             f"  states {res.states:,}  transitions {res.transitions:,}  depth {res.depth}  "
             f"{res.seconds:.2f} s wall ({res.rate:,.0f} states per CPU s)  {res.bytes_per_state:.0f} bytes/state "
             f"(peak +{res.peak_bytes / 2 ** 20:.0f} MB; stored graph {res.store_bytes_per_state:.0f} bytes/state)",
             "  CPU time " + "  ".join(f"{k} {v:.2f} s" for k, v in res.times.items()) + f"  ({res.cpu:.2f} s in all)"]
    for note in m.notes:
        lines.append(f"  note: {note}")
    if res.ok and not res.proof:
        lines.append(f"  no violation of {', '.join(i.name for i in m.invariants) or '-'} or deadlock "
                     "in the states searched")
    elif res.ok:
        lines.append(f"  invariants hold: {', '.join(i.name for i in m.invariants) or '-'}")
        lines.append("  no deadlock")
        for name, b in res.bounds.items():
            lines.append(f"  {name}: holds, bound {ms(b, m.tick_us)}" if b is not None
                         else f"  {name}: holds under weak fairness only (no tick bound)")
        if "bound_ticks" in s:
            lines.append(f"  K = {s['bound_ticks']} ticks = {s['bound_ms']} ms (tick {m.tick_us:.1f} us)")
        if "deadline" in s:
            d = s["deadline"]
            lines.append(f"  worst case {d['worst_ms']} ms {'<=' if d['meets'] else '>'} {d['bound_ms']:g} ms "
                         f"(seed {d['section']}): {'MEETS' if d['meets'] else 'FAILS'} the bound")
    lines.append(f"  never fired: {', '.join(res.never_fired) if res.never_fired else 'none (every rule fired)'}")
    for w in res.warnings:
        lines.append(f"  WARNING: {w}")
    if res.violation:
        v = res.violation
        lines.append(f"  VIOLATED {v.kind}: {v.prop}" + (f" -- {v.detail}" if v.detail else ""))
        lines.append("  counterexample (Mermaid sequenceDiagram):")
        lines += ["    " + x for x in s["mermaid"].splitlines()]
    elif not meets_deadline(res):
        lines.append("  BOUND EXCEEDED")
    elif not res.proof:
        lines.append("  NO VIOLATION FOUND (bitstate / hash-compact search: NOT a proof, see the estimate above)")
    elif m.responses and not res.bounds:
        lines.append("  SAFETY PROPERTIES HOLD (responses not checked)")
    else:
        lines.append("  ALL PROPERTIES HOLD")
    return "\n".join(lines)


def command_line(args) -> str:
    """The `arachnae check` command that found a counterexample, for the replay's header."""
    opts = [f"--{k} {v}" for k, v in (("variant", args.variant), ("bus", args.bus), ("size", args.size),
                                       ("scope", args.scope)) if v is not None]
    return " ".join(["arachnae check", args.model] + opts)


def run_check(args) -> int:
    spec = spec_adapter.load(args.spec)
    if args.variant == "seed" and args.model not in ("arbitration", "all"):
        raise UserError("--variant seed applies to the arbitration model only")
    models = build_models(args.model, spec, args.variant, args.bus, args.size, args.legs, not args.no_symmetry,
                          args.scope)
    results, ok = [], True
    for model in models:
        if getattr(args, "bitstate", None):
            from model_check.bitstate import explore_bitstate
            res, _ = explore_bitstate(model, args.bitstate, progress=not args.quiet)
        elif getattr(args, "hash_compact", None):
            from model_check.bitstate import explore_hash_compact
            res, _ = explore_hash_compact(model, args.hash_compact, progress=not args.quiet)
        else:   # compiled up front, every model (as SPIN compiles pan.c); the compile is timed apart
            res = explore(model, progress=not args.quiet, use_native=True, workers=getattr(args, "workers", 1))
        ok &= res.ok and meets_deadline(res)
        results.append(res)
        res.release()              # the graph is no longer needed: keep memory flat over `check all`
        if not args.json:
            print(text(res), flush=True)
        if getattr(args, "replay", None) and res.violation is not None:
            for path in replay.write(res, args.replay, command_line(args)):
                print(f"  replay: {path}  (run: arachnae sim run {path})", flush=True)
        if args.promela:
            from model_check import promela
            path = f"{args.promela.rstrip('/')}/{model.name.split('[')[0]}_{len(results)}.pml"
            with open(path, "w") as fh:
                fh.write(promela.emit(model))
    if args.json:
        print(json.dumps([summary(r) for r in results], indent=2))
    return 0 if ok else 1
