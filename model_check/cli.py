"""`arachnae check` and `arachnae timing`."""
from __future__ import annotations

import argparse
import json
import os
import tempfile

from arachnae.errors import UserError


def register(sub) -> None:
    c = sub.add_parser("check", help="model-check the protocols (arbitration, id_retry, post, reaction, all)")
    c.add_argument("model", help="arbitration | id_retry | post | reaction | all")
    c.add_argument("--variant", choices=("seed", "spec"), default="spec",
                   help="arbitration rule: exactly the seed's (seed) or the spec's (spec)")
    c.add_argument("--scope", choices=("colliders", "all"), default=None,
                   help="override the spec's backoff scope (who defers after a collision)")
    c.add_argument("--bus", default=None, help="bus to check (default: every bus the model applies to)")
    c.add_argument("--size", type=_positive, default=None,
                   help="use only the first N slaves of the bus (reaction: N other slaves per bus)")
    c.add_argument("--legs", type=_positive, default=None, help="POST: use only the first N legs")
    c.add_argument("--no-symmetry", action="store_true", help="POST: explore without symmetry reduction")
    c.add_argument("--promela", metavar="DIR", default=None, help="also write the Promela of each model to DIR")
    c.add_argument("--replay", metavar="DIR", default=None,
                   help="write each arbitration counterexample as a sim2d scenario in DIR (real node code)")
    c.add_argument("--spec", default=None, help="spec directory (default: the repository's spec/)")
    c.add_argument("--json", action="store_true", help="print the results as JSON")
    c.add_argument("--quiet", action="store_true", help="no progress lines on stderr")
    c.add_argument("--workers", type=_positive, default=1, metavar="N",
                   help="search on N threads sharing the visited set (every property checked; the same "
                        "states, ids, edges and verdicts as one thread)")
    c.add_argument("--bitstate", type=_bits, default=None, metavar="BITS",
                   help="bitstate search in 2^BITS bits of memory (%d..%d), safety only; prints the expected "
                        "omissions: a pass is then NOT a proof" % (BITSTATE_MIN, BITSTATE_MAX))
    c.add_argument("--hash-compact", type=_signature_bits, default=None, metavar="BITS",
                   help="store a BITS-bit signature per state instead of the state (%d..%d), safety only; prints "
                        "the expected omissions: a pass is then NOT a proof" % (COMPACT_MIN, COMPACT_MAX))
    c.set_defaults(func=_check)
    t = sub.add_parser("timing", help="worst-case POST, whisker-to-STOP and scan times from the spec")
    t.add_argument("--scope", choices=("colliders", "all"), default=None, help="override the backoff scope")
    t.add_argument("--spec", default=None, help="spec directory")
    t.add_argument("--json", action="store_true")
    t.set_defaults(func=_timing)


BITSTATE_MIN, BITSTATE_MAX = 10, 36       # 128 B .. 8 GiB of bits


def _bits(text: str) -> int:
    value = _positive(text)
    if not BITSTATE_MIN <= value <= BITSTATE_MAX:
        raise argparse.ArgumentTypeError(f"must be {BITSTATE_MIN} .. {BITSTATE_MAX}: {value}")
    return value


COMPACT_MIN, COMPACT_MAX = 16, 64          # signature bits of --hash-compact


def _signature_bits(text: str) -> int:
    value = _positive(text)
    if not COMPACT_MIN <= value <= COMPACT_MAX:
        raise argparse.ArgumentTypeError(f"must be {COMPACT_MIN} .. {COMPACT_MAX}: {value}")
    return value


def _positive(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1: {value}")
    return value


# which options each model reads (model_check.checks.build_models); any other given option is a mistake
_OPTIONS = {
    "arbitration": {"variant", "scope", "bus", "size"},
    "id_retry": {"bus", "size"},
    "post": {"legs", "no_symmetry"},
    "reaction": {"size"},          # --size: other slaves kept per bus (build_models: others)
    "all": {"variant", "scope", "size", "legs", "no_symmetry"},
}
_DEFAULTS = {"variant": "spec", "scope": None, "bus": None, "size": None, "legs": None, "no_symmetry": False}


def _check_options(args, spec) -> None:
    """Refuse options the model ignores and sizes it would silently cut (issue 10, item 9)."""
    from model_check import spec_adapter
    from model_check.checks import MODELS

    if args.model not in _OPTIONS:
        raise UserError(f"unknown model {args.model!r}; choose one of {', '.join(MODELS + ('all',))}")
    given = [k for k, default in _DEFAULTS.items() if getattr(args, k) != default]
    unused = [k for k in given if k not in _OPTIONS[args.model]]
    if unused:
        flag = "--" + unused[0].replace("_", "-")
        raise UserError(f"check {args.model}: {flag} does not apply to this model "
                        f"(it takes {', '.join('--' + o.replace('_', '-') for o in sorted(_OPTIONS[args.model]))})")
    if args.bus is not None and args.bus not in spec.buses:
        raise UserError(f"--bus {args.bus}: unknown bus; buses: {', '.join(spec.buses)}")
    if args.size is not None:
        for bus, slaves in _slave_counts(spec, args.model, args.bus, spec_adapter).items():
            if args.size > slaves:
                raise UserError(f"--size {args.size}: bus {bus} has only {slaves} slave(s) in this model "
                                f"(1 .. {slaves})")
    if args.legs is not None:
        legs = max((n.leg for n in spec.nodes if n.leg is not None), default=0)
        if args.legs > legs:
            raise UserError(f"--legs {args.legs}: the spec has {legs} legs (1 .. {legs})")


def _slave_counts(spec, model: str, bus: str | None, spec_adapter) -> dict[str, int]:
    """Slaves per bus that `--size` would cut, for each bus the model checks (the buses
    model_check.checks.build_models picks)."""
    counts: dict[str, int] = {}
    if model in ("arbitration", "all"):
        buses = [bus] if bus else spec_adapter.contended_buses(spec)
        for b in buses:
            counts[f"{b} (arbitration)"] = len(spec_adapter.arbitration(spec, b).slaves)
    if model in ("id_retry", "all"):
        buses = [bus] if bus else spec_adapter.contended_buses(spec)
        for b in buses:
            counts[f"{b} (id_retry)"] = len(spec_adapter.identification(spec, b).slaves)
    return counts


def _check_promela_dir(path: str) -> None:
    """--promela must be a folder we can write into; found out before the (possibly long) check runs."""
    if not os.path.isdir(path):
        raise UserError(f"--promela {path}: no such folder")
    try:
        with tempfile.TemporaryFile(dir=path):
            pass
    except OSError as exc:
        raise UserError(f"--promela {path}: cannot write there ({exc.strerror})") from None


def _check(args) -> int:
    from model_check import spec_adapter
    from model_check.checks import run_check

    spec = spec_adapter.load(args.spec)
    _check_options(args, spec)
    if args.promela:
        _check_promela_dir(args.promela)
    modes = [flag for flag, on in (("--workers", args.workers > 1), ("--bitstate", args.bitstate),
                                   ("--hash-compact", args.hash_compact)) if on]
    if len(modes) > 1:
        raise UserError(f"{' and '.join(modes)}: choose one search mode")
    try:
        return run_check(args)
    except BrokenPipeError:
        raise                               # stdout piped into `head`: arachnae.cli ends quietly
    except OSError as exc:
        if args.promela:                    # e.g. the --promela folder filled up or vanished mid-run
            raise UserError(f"--promela {args.promela}: cannot write ({exc.strerror or exc})") from None
        raise UserError(f"check: {exc.filename or 'output'}: {exc.strerror or exc}") from None


def _timing(args) -> int:
    from model_check import spec_adapter, timing
    spec = spec_adapter.load(args.spec)
    figures, warnings = timing.report(spec, args.scope)
    if args.json:
        print(json.dumps({"figures": [f.__dict__ for f in figures], "warnings": warnings}, indent=2))
    else:
        for f in figures:
            value = "n/a" if f.ms is None else f"{f.ms:.1f} ms"
            bound = f" (bound {f.bound_ms:g} ms, seed {f.section})" if f.bound_ms else f" (seed {f.section})"
            print(f"{f.name}: {value}{bound} -- {f.verdict}")
            for part in f.parts:
                print(f"    {part}")
        for w in warnings:
            print(f"WARNING: {w}")
    return 0
