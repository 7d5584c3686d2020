"""Fuzzing the generated Python codec (arachnae_proto), differentially against the generated C.

Input layout as fuzz_frame.c: byte 0 is the receiving node's own address, the rest
the bytes on the line. For every input:
  1. frame.parse either returns a Frame or raises CodecError (no other exception);
  2. the byte Parser (feed every byte, then gap) reaches the same verdict;
  3. a parsed frame re-encodes to exactly the input bytes;
  4. the generated C (arachnae_frame_decode, through ctypes) gives the same verdict
     as Python, error kind for error kind.
Inputs come from hypothesis (bounded number of examples), starting from the
committed seed corpus fuzz/corpus/frame, and half of them get a correct CRC so the
decoders behind the checksum are reached.

    python fuzz/python_fuzz.py [--examples N]    exit 1 on the first disagreement
"""
from __future__ import annotations

import argparse
import ctypes
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
CORPUS = Path(__file__).resolve().parent / "corpus" / "frame"
GEN_C = REPO / "generated" / "c"
if str(REPO / "generated" / "python") not in sys.path:
    sys.path.insert(0, str(REPO / "generated" / "python"))

from arachnae_proto import CodecError, ErrorKind, frame  # noqa: E402

ARACHNAE_NONE = len(ErrorKind)   # the C enum's value after the last error kind


def build_c_codec(out_dir: Path) -> ctypes.CDLL:
    """The generated C codec as a shared library (gcc, the same strict flags as the firmware)."""
    so = out_dir / "libarachnae.so"
    srcs = sorted(str(p) for p in GEN_C.glob("*.c") if not p.name.startswith("node_"))
    subprocess.run(["gcc", "-std=c99", "-O1", "-shared", "-fPIC", "-Wall", "-Wextra", "-Werror",
                    f"-I{GEN_C}", *srcs, "-o", str(so)], check=True)
    lib = ctypes.CDLL(str(so))
    # arachnae_status is one byte (uint8_t, issue 15): c_int would read the register's undefined upper bytes
    status = ctypes.c_uint8
    lib.arachnae_frame_decode.restype = status
    lib.arachnae_frame_decode.argtypes = [ctypes.c_char_p, ctypes.c_uint16, ctypes.c_uint16,
                                          ctypes.c_void_p, ctypes.c_void_p]
    # the reflection layer (arachnae_generic.h): fields by index, tagged-union encode/decode
    msg, u8p = ctypes.c_void_p, ctypes.POINTER(ctypes.c_uint8)
    signatures = {
        "arachnae_field_set": [msg, ctypes.c_uint8, ctypes.c_uint16, ctypes.c_int32],
        "arachnae_field_get": [msg, ctypes.c_uint8, ctypes.c_uint16, ctypes.POINTER(ctypes.c_int32)],
        "arachnae_encode_payload": [msg, ctypes.c_char_p, ctypes.c_uint16, u8p],
        "arachnae_decode_payload": [ctypes.c_uint8, ctypes.c_char_p, ctypes.c_uint8, msg],
    }
    for name, argtypes in signatures.items():
        fn = getattr(lib, name)
        fn.restype, fn.argtypes = status, argtypes
    return lib


def python_verdict(data: bytes, own: int) -> tuple[int, bytes | None]:
    """(error kind or OK, re-encoded frame when it parsed)."""
    try:
        f = frame.parse(data, own)
    except CodecError as exc:
        return int(exc.kind), None
    return int(ErrorKind.OK), frame.build(f.dst, f.src, f.message)


def parser_verdict(data: bytes, own: int) -> int:
    """Byte parser: the last verdict feed() gave (OVERSIZE supersedes OK), else the gap's."""
    p = frame.Parser(own)
    verdict = None
    for b in data:
        try:
            if p.feed(b) is not None:
                verdict = int(ErrorKind.OK)
        except CodecError as exc:
            verdict = int(exc.kind)
    try:
        p.gap()
    except CodecError as exc:
        if verdict is None:
            verdict = int(exc.kind)
    return verdict if verdict is not None else ARACHNAE_NONE


class Disagreement(AssertionError):
    pass


def check(data: bytes, lib: ctypes.CDLL) -> None:
    if not data:
        return
    own, line = data[0], data[1:]
    kind, again = python_verdict(line, own)
    if again is not None and again != line:
        raise Disagreement(f"{data.hex()}: re-encoding gives {again.hex()}")
    if line:
        pk = parser_verdict(line, own)
        if pk != kind:
            raise Disagreement(f"{data.hex()}: Parser says {pk}, parse says {kind}")
    msg = ctypes.create_string_buffer(1024)
    ck = lib.arachnae_frame_decode(line, len(line), own, None, msg)
    if ck != kind:
        raise Disagreement(f"{data.hex()}: C says {ck}, Python says {kind}")


def with_crc(data: bytes) -> bytes:
    if len(data) < 3:
        return data
    body = data[1:-2]
    return data[:1] + body + frame.crc(body).to_bytes(2, "big")


def seeds() -> list[bytes]:
    return [p.read_bytes() for p in sorted(CORPUS.glob("*"))]


def run(examples: int, lib: ctypes.CDLL) -> int:
    from hypothesis import HealthCheck, given, settings, strategies as st

    for s in seeds():
        check(s, lib)
        check(with_crc(s), lib)
    corpus = seeds()

    @st.composite
    def inputs(draw):
        base = draw(st.sampled_from(corpus)) if draw(st.booleans()) else draw(st.binary(max_size=270))
        data = bytearray(base)
        for _ in range(draw(st.integers(0, 4))):       # a few byte-level mutations of a seed
            if data and draw(st.booleans()):
                data[draw(st.integers(0, len(data) - 1))] = draw(st.integers(0, 255))
            else:
                data.insert(draw(st.integers(0, len(data))), draw(st.integers(0, 255)))
        data = bytes(data)
        return with_crc(data) if draw(st.booleans()) else data

    @settings(max_examples=examples, deadline=None, derandomize=True, database=None,
              suppress_health_check=list(HealthCheck))
    @given(inputs())
    def prop(data: bytes) -> None:
        check(data, lib)

    prop()
    return len(corpus)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--examples", type=int, default=20000, help="hypothesis examples (default 20000)")
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        lib = build_c_codec(Path(tmp))
        try:
            n = run(args.examples, lib)
        except Disagreement as exc:
            print(f"python_fuzz: {exc}", file=sys.stderr)
            return 1
    print(f"python_fuzz: {n} seeds and {args.examples} generated inputs, Python, its byte parser and C agree")
    return 0


if __name__ == "__main__":
    sys.exit(main())
