"""Subcommands of the spec and its generated code: `spec check`, `spec nodes`, `codegen`, `docs`."""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from arachnae.errors import UserError


def register(sub: argparse._SubParsersAction) -> None:
    spec = sub.add_parser("spec", help="check or show the spec")
    spec_sub = spec.add_subparsers(dest="spec_command", metavar="ACTION", required=True)
    check = spec_sub.add_parser("check", help="validate spec/nodes.yaml and spec/messages.yaml")
    check.add_argument("--spec", type=Path, default=None, metavar="DIR", help="spec folder (default: spec/)")
    check.set_defaults(func=_spec_check)
    nodes = spec_sub.add_parser("nodes", help="print the node table with buses and masters")
    nodes.add_argument("--spec", type=Path, default=None, metavar="DIR")
    nodes.set_defaults(func=_spec_nodes)

    gen = sub.add_parser("codegen", help="generate C, Python and the conformance vectors from the spec")
    gen.add_argument("--spec", type=Path, default=None, metavar="DIR")
    gen.add_argument("--check", action="store_true", help="fail if the committed generated files are out of date")
    gen.add_argument("--out", type=Path, default=None, metavar="DIR",
                     help="the generated tree to write or check (default: the repository's generated/)")
    gen.set_defaults(func=_codegen)

    docs = sub.add_parser("docs", help="write the HTML message reference (nodes, buses, messages, rules) from the spec")
    docs.add_argument("--spec", type=Path, default=None, metavar="DIR")
    docs.add_argument("--out", type=Path, default=Path("build/docs"), metavar="DIR",
                      help="folder for index.html (default build/docs)")
    docs.add_argument("--force", action="store_true",
                      help="replace an index.html there even if `arachnae docs` did not write it")
    docs.set_defaults(func=_docs)



def _spec_check(args: argparse.Namespace) -> int:
    from codegen.load import load_spec
    from codegen.usage import warnings

    spec = load_spec(args.spec)
    for warning in warnings(spec):   # warnings never fail the check; errors (UserError) do
        sys.stderr.write(warning + "\n")
    print(f"spec ok: {len(spec.nodes)} nodes on {len(spec.buses)} buses, {len(spec.messages)} messages, "
          f"largest frame {spec.max_frame} bytes, sha256 {spec.hash[:12]}")
    return 0


def _spec_nodes(args: argparse.Namespace) -> int:
    from codegen.load import load_spec

    spec = load_spec(args.spec)
    print(f"{'node':9} {'addr':5} {'lvl':3} {'bus':8} {'bus master':10} {'masters':8} {'status':9} seed")
    for n in spec.nodes:
        master = spec.buses[n.bus].master if n.bus else "-"
        print(f"{n.short:9} 0x{n.address:02X}  {n.level:<3} {n.bus or '-':8} {master:10} {n.masters or '-':8} {n.status:9} {n.section}")
    print(f"{'(all)':9} 0x{spec.broadcast:02X}  broadcast, never a node address (seed 3.2.1)")
    return 0


def _docs(args: argparse.Namespace) -> int:
    from codegen.html import write_reference
    from codegen.load import load_spec

    if args.out.exists() and not args.out.is_dir():
        raise UserError(f"--out {args.out}: exists and is not a folder")
    spec = load_spec(args.spec)
    try:
        page = write_reference(spec, args.out, force=args.force)
    except OSError as exc:
        raise UserError(f"--out {args.out}: cannot write ({exc.strerror or exc})") from None
    print(f"wrote {page}: {len(spec.nodes)} nodes, {len(spec.buses)} buses, {len(spec.messages)} messages")
    return 0


def _codegen(args: argparse.Namespace) -> int:
    from codegen.generate import GENERATED, render, stale, write
    from codegen.load import load_spec

    start = time.perf_counter()
    out = args.out if args.out is not None else GENERATED
    spec = load_spec(args.spec)
    files = render(spec)
    if args.check:
        out_of_date = stale(files, out)
        if out_of_date:
            listed = ", ".join(str(p) for p in out_of_date[:5]) + (" ..." if len(out_of_date) > 5 else "")
            raise UserError(f"generated files are out of date with the spec: {listed} (run `make codegen`)")
        print(f"generated files up to date ({len(files)} files)")
        return 0
    changed = write(files, out)
    print(f"codegen: {len(files)} files, {len(changed)} changed, {time.perf_counter() - start:.2f} s")
    return 0


