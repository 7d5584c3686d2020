"""Codec and generator benchmarks (issue 2): prints figures, asserts nothing.

Figures are compared with references measured in the same run, because these
machines are noisy: a bare CRC + struct loop (the floor for any Python decoder)
and, when installed, pymavlink parsing a HEARTBEAT.
"""
from __future__ import annotations

import struct
import subprocess
import sys
import time
from binascii import crc_hqx
from pathlib import Path

from arachnae_proto import frame
from arachnae_proto import messages as M

REPO = Path(__file__).resolve().parent.parent


def rate(fn, data, seconds: float = 1.0) -> float:
    """Calls per second of fn(data), best of three runs."""
    best = 0.0
    for _ in range(3):
        n, start = 0, time.perf_counter()
        while time.perf_counter() - start < seconds / 3:
            for _ in range(1000):
                fn(data)
            n += 1000
        best = max(best, n / (time.perf_counter() - start))
    return best


def floor_decode(data: bytes, _s=struct.Struct(">BH")):
    if crc_hqx(data[:-2], 0xFFFF) != int.from_bytes(data[-2:], "big"):
        raise ValueError
    return _s.unpack(data[4:-2])


def mavlink_rate() -> float | None:
    try:
        from pymavlink.dialects.v20 import common as mav
    except ImportError:
        return None
    m = mav.MAVLink(None)
    packet = mav.MAVLink_heartbeat_message(2, 3, 0, 0, 4, 3).pack(m)

    def parse(data):
        m.decode(bytearray(data))

    return rate(parse, packet)


def main() -> None:
    typical = frame.build(0x04, 0x27, M.XmitDataUsrc(distance=123, angle=45))   # a sonar reading, 9 bytes
    ours = rate(frame.parse, typical)
    floor = rate(floor_decode, typical)
    print(f"python decode (XMIT_DATA_USRC, {len(typical)} B, checksum included): {ours:,.0f} frames/s   target >= 300,000")
    print(f"  reference, bare crc_hqx + struct.unpack in this run:   {floor:,.0f} frames/s   (ours = {ours / floor:.2f} x floor)")
    mav = mavlink_rate()
    if mav is None:
        print("  reference, pymavlink: not installed (pip install pymavlink); published figure ~100,000 packets/s")
    else:
        print(f"  reference, pymavlink HEARTBEAT decode in this run:     {mav:,.0f} packets/s (ours = {ours / mav:.1f} x pymavlink)")
    start = time.perf_counter()
    subprocess.run([str(REPO / ".venv" / "bin" / "arachnae") if (REPO / ".venv").exists() else "arachnae", "codegen"],
                   check=True, capture_output=True)
    print(f"make codegen (arachnae codegen, whole process): {time.perf_counter() - start:.2f} s   target <= 2 s")


if __name__ == "__main__":
    sys.exit(main())
