"""One short simulation with bus faults, shared by the capture tests (pcapng, Wireshark, sigrok)."""
from __future__ import annotations

import csv
from pathlib import Path
from typing import NamedTuple

import pytest

# 3 s of POST and start-up traffic on every bus, with corrupt frames on the first and sensor
# buses, losses on the leg bus and losses plus late deliveries on joints3.
SCENARIO = """name: capture_test
duration: 3
arena: {size: [4, 3]}
robot: {pose: [1, 1.5, 0]}
faults:
  - {at: 0.2, until: 3.0, bus: first, corrupt: 0.2}
  - {at: 0.2, until: 3.0, bus: sensor, corrupt: 0.2}
  - {at: 0.2, until: 3.0, bus: leg, loss: 0.1}
  - {at: 0.2, until: 3.0, bus: joints3, loss: 0.05, delay: 0.004}
"""


class TraceRow(NamedTuple):
    start_s: float
    end_s: float
    bus: str
    sender: str
    src: str
    dst: str
    message: str
    data: bytes
    flags: tuple[str, ...]


def read_trace(path: Path) -> list[TraceRow]:
    """The frames of trace.tsv (its debug-port rows, bus `debug`, are no frames on a wire)."""
    from tracecheck.trace import DEBUG_BUS

    with open(path, newline="") as fh:
        rows = [r for r in csv.DictReader(fh, delimiter="\t") if r["bus"] != DEBUG_BUS]
    return [TraceRow(float(r["start_s"]), float(r["end_s"]), r["bus"], r["sender"], r["src"], r["dst"], r["message"],
                     bytes.fromhex(r["bytes"]), tuple(f for f in r["flags"].split(",") if f)) for r in rows]


@pytest.fixture(scope="session")
def bus_run(tmp_path_factory) -> Path:
    """The output folder of `arachnae sim run` on SCENARIO."""
    from arachnae.cli import main

    d = tmp_path_factory.mktemp("bus_run")
    (d / "s.yaml").write_text(SCENARIO)
    assert main(["sim", "run", str(d / "s.yaml"), "--out", str(d / "run")]) == 0
    return d / "run"


@pytest.fixture(scope="session")
def trace(bus_run) -> list[TraceRow]:
    return read_trace(bus_run / "trace.tsv")


@pytest.fixture
def tool_env(tmp_path) -> dict:
    """An environment for tshark/sigrok-cli that reads no personal configuration."""
    import os

    env = dict(os.environ)
    env.update(HOME=str(tmp_path), XDG_CONFIG_HOME=str(tmp_path / "config"), XDG_DATA_HOME=str(tmp_path / "data"))
    return env


HOSTILE_UNIT = 'V"]]\\\n--\u00b0\'\'\'"""'   # quotes, a Lua long-bracket end, a backslash, a newline, a comment start


@pytest.fixture
def hostile_spec(tmp_path, repo):
    """The spec with XMIT_DATA_PSC.voltage's unit and doc full of Lua and Python syntax."""
    import json
    import shutil

    from codegen.load import load_spec

    spec_dir = tmp_path / "spec"
    shutil.copytree(repo / "spec", spec_dir)
    text = (spec_dir / "messages.yaml").read_text()
    line = '{name: voltage, type: uint, bits: 8, unit: V, scale: "1/200", offset: 4, range: [4.2, 5.0]}'
    assert line in text
    doc = 'end ]] os.exit(1) --[[ """ \'\'\''
    hostile = line.replace("unit: V,", f"unit: {json.dumps(HOSTILE_UNIT)}, doc: {json.dumps(doc)},")
    text = text.replace(line, hostile)
    # SET_ALARM_PSC's limit is compared with that voltage (compared_with), and the lint wants one unit for both
    limit = '{name: limit, type: uint, bits: 8, unit: V, scale: "1/200", offset: 4, range: [4.2, 5.0], compared_with: XMIT_DATA_PSC}'
    assert limit in text
    text = text.replace(limit, limit.replace("unit: V,", f"unit: {json.dumps(HOSTILE_UNIT)},"))
    (spec_dir / "messages.yaml").write_text(text)
    return load_spec(spec_dir)
