"""The `arachnae` entry point: decode, and one-line errors for user mistakes."""
from __future__ import annotations

import subprocess
import sys

from arachnae_proto import frame
from arachnae_proto import messages as M


def arachnae(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "arachnae", *args], capture_output=True, text=True)


def test_decode_names_nodes_fields_and_units() -> None:
    data = frame.build(0x04, 0x27, M.XmitDataUsrc(distance=255, angle=90))
    run = arachnae("decode", data.hex())
    assert run.returncode == 0, run.stderr
    assert run.stdout.splitlines()[0] == "USRC -> SPU  XMIT_DATA_USRC (opcode 0x47, seed 3.2.11)"
    assert "10 m (raw 255)" in run.stdout and "90 deg" in run.stdout


def test_decode_says_what_is_wrong_with_a_malformed_frame() -> None:
    data = bytearray(frame.build(0x04, 0x27, M.XmitDataUsrc(distance=1, angle=1)))
    data[-1] ^= 0xFF
    run = arachnae("decode", data.hex())
    assert run.returncode == 1 and run.stderr.startswith("decode: CHECKSUM: ")
    assert len(run.stderr.strip().splitlines()) == 1
    run = arachnae("decode", data[:5].hex())
    assert run.returncode == 1 and run.stderr.startswith("decode: TRUNCATED: ")


def test_bad_arguments_are_one_line_with_exit_2() -> None:
    run = arachnae("no-such-command")
    assert run.returncode == 2 and len(run.stderr.strip().splitlines()) == 1
    run = arachnae("decode", "xyz")
    assert run.returncode == 1 and run.stderr.strip() == "decode: 'xyz' is not a hex string"
