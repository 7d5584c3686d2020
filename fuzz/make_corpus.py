"""Seed corpus of the frame fuzzers, built from the shared vectors (generated/vectors/vectors.txt).

Each seed is one file: byte 0 is the receiving node's own address, the rest the
bytes on the line (the input layout of fuzz_frame.c and python_fuzz.py). `msg`
lines are received by their destination, `bad` lines by the address they name.

    python fuzz/make_corpus.py            rewrite fuzz/corpus/frame/ (committed)
    python fuzz/make_corpus.py --check    exit 1 if the committed corpus is stale
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
VECTORS = REPO / "generated" / "vectors" / "vectors.txt"
CORPUS = Path(__file__).resolve().parent / "corpus" / "frame"


def _hex(text: str) -> bytes:
    return b"" if text == "-" else bytes.fromhex(text)


def seeds(vectors: Path = VECTORS) -> dict[str, bytes]:
    out: dict[str, bytes] = {}
    for lineno, line in enumerate(vectors.read_text().splitlines(), 1):
        parts = line.split()
        if not parts or parts[0].startswith("#"):
            continue
        if parts[0] == "msg":
            frame = _hex(parts[3])
            out[f"msg_{parts[1]}_{parts[2]}"] = bytes([frame[0]]) + frame
        elif parts[0] == "bad" and parts[2] != "-":   # byte 0 names one own address; "any" has no byte
            out[f"bad_{parts[1]}"] = bytes([int(parts[2], 16)]) + _hex(parts[3])
    if not out:
        raise SystemExit(f"{vectors}: no msg or bad lines")
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--check", action="store_true", help="compare instead of writing")
    args = ap.parse_args(argv)
    want = seeds()
    have = {p.name: p.read_bytes() for p in CORPUS.glob("*")} if CORPUS.is_dir() else {}
    if args.check:
        stale = sorted(set(want) ^ set(have) | {k for k in want if k in have and want[k] != have[k]})
        if stale:
            print(f"fuzz/corpus/frame is stale ({len(stale)} files, e.g. {stale[0]}): run python fuzz/make_corpus.py",
                  file=sys.stderr)
            return 1
        print(f"fuzz/corpus/frame: {len(want)} seeds match {VECTORS.relative_to(REPO)}")
        return 0
    CORPUS.mkdir(parents=True, exist_ok=True)
    for name in set(have) - set(want):
        (CORPUS / name).unlink()
    for name, data in want.items():
        (CORPUS / name).write_bytes(data)
    print(f"wrote {len(want)} seeds to {CORPUS.relative_to(REPO)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
