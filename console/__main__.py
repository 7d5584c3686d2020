"""`python -m console [stdio|pty|URL]`: the RCP console on its own, showing the frames it would send.

Ctrl-C or Ctrl-D quits. Each key's message appears on LCD line 1 as the
frame UIC/RCP -> MCP the node would put on the first-level bus (hex).
"""
from __future__ import annotations

import sys

from arachnae_proto.frame import build
from arachnae_proto.network import ADDRESS_OF

from console.terminal import attach

QUIT = (3, 4)   # Ctrl-C, Ctrl-D: raw mode delivers them as bytes


def main(argv: list[str]) -> int:
    console = attach(argv[0] if argv else "stdio")
    if console.peer:
        print(f"console on {console.peer}: connect a terminal program to it", file=sys.stderr)
    console.show_lcd(0, "ARACHNAE II")
    console.show_lcd(1, "Enter command")      # seed 3.2.6 resident message 4
    try:
        while True:
            keys = console.port.read(0.5)
            if any(b in QUIT for b in keys):
                return 0
            for msg in console.feed(keys):
                console.show_lcd(1, build(ADDRESS_OF["MCP"], ADDRESS_OF["UIC/RCP"], msg).hex())
    except KeyboardInterrupt:
        return 0
    finally:
        console.close()


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
