"""Shared runs for the trace tests: a short POST scenario with missing nodes, and the checker's replay."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

# PSC (optional, sensor bus) and LCP(1) with its leg's JACs are not fitted: POST is DEGRADED, and the
# masters' ID_REQ retries and timeouts to the missing nodes are on the wire; the operator's halt key puts a
# MOVE_RELAYED on the first-level bus (an idle NP3 sends no MOVE after POST)
MISSING = """name: missing
duration: 3
arena: {size: [4, 3]}
robot: {pose: [2, 1.5, 0], task: idle, absent: [PSC, "LCP(1)"]}
operator: [{at: 2.0, keys: H}]
expect: {post: DEGRADED}
"""


@pytest.fixture(scope="session")
def missing_scenario(tmp_path_factory) -> Path:
    p = tmp_path_factory.mktemp("scen") / "missing.yaml"
    p.write_text(MISSING)
    return p


@pytest.fixture(scope="session")
def replay_dir(tmp_path_factory) -> Path:
    """`arachnae check arbitration --variant seed --bus sensor --size 2 --replay DIR`: the collide-forever lasso."""
    out = tmp_path_factory.mktemp("replay")
    p = subprocess.run([sys.executable, "-m", "arachnae", "check", "arbitration", "--variant", "seed", "--bus",
                        "sensor", "--size", "2", "--quiet", "--replay", str(out)], capture_output=True, text=True,
                       timeout=300)
    assert p.returncode == 1, p.stderr            # the seed variant violates served_USRC
    assert "replay:" in p.stdout
    return out


@pytest.fixture(scope="session")
def corrupt_id_scenario(tmp_path_factory) -> Path:
    """The missing-nodes POST with the sensor bus corrupting 40 % of its frames while the SPU identifies its
    sensors: ID_REQs and ID_ACKs are heard corrupt (the seed 3.2.2 echo resend and the retry both happen)."""
    p = tmp_path_factory.mktemp("scen") / "corrupt_id.yaml"
    p.write_text(MISSING.replace("duration: 3", "duration: 2.5")
                 + "faults:\n  - {at: 0.0, until: 2.0, bus: sensor, corrupt: 0.4}\n")
    return p
