from __future__ import annotations

import fcntl
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
FIRMWARE = REPO / "firmware"


def make(*targets: str, **variables: str) -> subprocess.CompletedProcess:
    """make -C firmware; a failure shows the compiler's last lines."""
    args = ["make", "-C", str(FIRMWARE), "-j2", f"PYTHON={sys.executable}", *targets]
    args += [f"{k}={v}" for k, v in variables.items()]
    # pytest-xdist workers share firmware/build: one make at a time, the others wait and find it up to date
    FIRMWARE.joinpath("build").mkdir(exist_ok=True)
    with open(FIRMWARE / "build" / ".make.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        r = subprocess.run(args, capture_output=True, text=True)
    if r.returncode != 0:
        pytest.fail(f"{' '.join(args)} failed:\n{r.stdout[-3000:]}\n{r.stderr[-3000:]}")
    return r


@pytest.fixture(scope="session")
def firmware_built() -> Path:
    """The whole build matrix, every role image and the SIL programs (incremental)."""
    make("all")
    return FIRMWARE / "build"
