"""`python -m console [stdio|pty|serial:DEV] [--pace X]`: drive an idle robot in an open room by hand.

The whole network is simulated (scenarios/interactive/console.yaml); the
UIC/RCP node reads your keys from the chosen line. Ctrl-C ends the run.
"""
from __future__ import annotations

import sys
from pathlib import Path

SCENARIO = Path(__file__).resolve().parent.parent / "scenarios" / "interactive" / "console.yaml"


def main(argv: list[str]) -> int:
    from arachnae.cli import main as arachnae_main

    where = argv[0] if argv and not argv[0].startswith("-") else "stdio"
    rest = argv[1:] if argv and not argv[0].startswith("-") else argv
    return arachnae_main(["sim", "run", str(SCENARIO), "--console", where, "--out", "sim-out/console", *rest])


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
