"""`arachnae trace check TRACE`: a saved bus trace (simulated or captured) against the verified protocol."""
from __future__ import annotations

import argparse
import json
from typing import Any


def register(sub: Any) -> None:
    t = sub.add_parser("trace", help="bus traces: validate against the verified protocol")
    tsub = t.add_subparsers(dest="trace_command", metavar="TRACECOMMAND", parser_class=type(t))
    tsub.required = True
    c = tsub.add_parser("check", help="check a trace.tsv: exit 1 and one line per protocol violation")
    c.add_argument("trace", help="trace.tsv written by `arachnae sim run` (or captured in the same columns), "
                                 "or a pcapng capture (a run's bus.pcapng, `arachnae monitor --pcapng`)")
    c.add_argument("--arbitration", action="append", default=[], metavar="BUS=VARIANT",
                   help="the rule a contended bus ran: seed or spec (default spec), e.g. sensor=seed")
    c.add_argument("--spec", default=None, help="spec directory (default: the repository's spec/)")
    c.add_argument("--untimed", action="store_true",
                   help="the capture's time stamps are not the line's (a pty, a buffering USB adapter): "
                        "check only the rules that need no clock")
    c.add_argument("--json", action="store_true", help="print the summary as JSON")
    c.set_defaults(func=_check)


def _variants(items: list[str], spec: Any) -> dict[str, str]:
    from arachnae.errors import UserError
    out = {}
    for item in items:
        bus, sep, variant = item.partition("=")
        if not sep or bus not in spec.buses or variant not in ("seed", "spec"):
            raise UserError(f"--arbitration: expected BUS=seed|spec with a bus of the spec, got {item!r}")
        out[bus] = variant
    return out


def _check(args: argparse.Namespace) -> int:
    from model_check.spec_adapter import load
    from tracecheck.trace import read
    from tracecheck.validate import validate

    spec = load(args.spec)
    variants = _variants(args.arbitration, spec)
    trace = read(args.trace, set(spec.buses), spec)
    report = validate(trace, spec, variants, timed=not args.untimed)
    if args.json:
        print(json.dumps(dict(report.metrics(), all=[str(v) for v in report.violations]), indent=2))
    else:
        for v in report.violations:
            print(v)
        m = report.metrics()
        print(f"{args.trace}: {len(trace.frames)} frames, {m['violations']} protocol violation(s); "
              f"requests {m['requests']} (served {m['served']}, declined {m['declined']}, unchecked {m['unchecked']}), "
              + (f"longest wait {m['max_wait_slots']} slots, K {m['k_slots']}" if not args.untimed else
                 f"untimed: checked {m['checked']}"))
        for rule, why in m["skipped"].items():
            print(f"{args.trace}: {rule} skipped: {why}")
    return 1 if report.violations else 0
