"""Build and run the C decode benchmark (bench/c_bench.c); prints figures, asserts nothing timed.

    python bench/c_bench.py [--cc gcc] [--flags "-O2 ..."]

Target from issue 2: >= 20 million frames/s for a typical frame (XMIT_DATA_USRC,
MOVE_RELAYED) including the checksum check, at -O2 on the development host. The
references in the same run (memcpy + CRC) put the figure in proportion to the host.
"""
from __future__ import annotations

import argparse
import shlex
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
GEN = REPO / "generated" / "c"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cc", default="gcc")
    ap.add_argument("--flags", default="-O2", help="optimisation flags (default -O2)")
    args = ap.parse_args()
    sources = sorted(GEN.glob("arachnae_*.c")) + sorted(GEN.glob("msg_*.c")) + sorted(GEN.glob("log10_*.c"))
    if not sources:
        sys.stderr.write("generated/c is empty: run the generator first\n")
        return 1
    with tempfile.TemporaryDirectory() as tmp:
        exe = Path(tmp) / "c_bench"
        for label, extra in (("default CRC (shift/xor)", []), ("-DARACHNAE_CRC_BITWISE", ["-DARACHNAE_CRC_BITWISE"])):
            cmd = [args.cc, "-std=c99", "-Wall", "-Wextra", *shlex.split(args.flags), *extra, f"-I{GEN}",
                   *map(str, sources), str(REPO / "bench" / "c_bench.c"), "-o", str(exe)]
            subprocess.run(cmd, check=True)
            print(f"== {args.cc} {args.flags} {label}")
            sys.stdout.flush()
            res = subprocess.run([str(exe)])
            if res.returncode != 0:
                return res.returncode
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
