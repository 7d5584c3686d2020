"""The single `arachnae` entry point; each part of the toolkit adds its own subcommands.

A part registers through a module-level `register(subparsers)` in its own
`cli.py`, so this file never grows with the features behind it.
"""
from __future__ import annotations

import argparse
import importlib
import sys
from typing import Sequence

from arachnae.errors import UserError

# Parts that contribute subcommands; a part that is not installed yet is skipped.
PARTS = ("codegen.cli", "model_check.cli", "tracecheck.cli", "sim2d.cli", "captures.cli")


class _Parser(argparse.ArgumentParser):
    """argparse, but a usage mistake is one line and exit 2."""

    def error(self, message: str) -> None:  # type: ignore[override]
        sys.stderr.write(f"{self.prog}: error: {message}\n")
        raise SystemExit(2)


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="arachnae", description="ARACHNAE II toolkit")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    for name in PARTS:
        try:
            module = importlib.import_module(name)
        except ModuleNotFoundError as exc:
            if exc.name and name.startswith(exc.name):
                continue
            raise
        module.register(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except UserError as exc:
        sys.stderr.write(f"{exc}\n")
        return exc.exit_code
    except KeyboardInterrupt:
        sys.stderr.write("interrupted\n")
        return 130
    except BrokenPipeError:  # output piped into `head` and the like
        sys.stderr.close()
        return 0


if __name__ == "__main__":
    raise SystemExit(main())
