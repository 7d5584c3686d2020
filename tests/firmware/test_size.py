"""Issue 6.2, 6.5 and 15: size per role and stack depth, from the linker maps and the call graph."""
from __future__ import annotations

import json
import subprocess
import sys

import pytest

from tests.firmware.conftest import FIRMWARE, make

SENSORS = ("usrc", "tpsc", "irrc", "isc", "tsc", "lsc", "psc")
# Issue 15 targets (AVR flash, codec + skeleton): not reached yet, see test_issue_15_targets.
SENSOR_TARGET, TPSC_TARGET, ROLE_TARGET = 1024, 633, 2048
# What the generated C reaches today, with a little room: a regression past these fails.
SENSOR_CEILING, TPSC_CEILING, ROLE_CEILING = 1420, 1240, 2330


def report(build, *extra):
    r = subprocess.run([sys.executable, str(FIRMWARE / "size_report.py"), "--build", str(build), *extra],
                       capture_output=True, text=True)
    return r, [row for row in json.loads((build / "size.json").read_text()) if row["target"] in ("avr", "m0")]


def avr_codec_skeleton(rows) -> dict[str, int]:
    return {r["role"]: sum(r[p][k] for p in ("codec", "skeleton") for k in ("text", "data"))
            for r in rows if r["target"] == "avr" and r["role"] != "baseline_tpsc"}


def test_size_report_runs_and_the_codec_has_no_data_or_bss(firmware_built, spec):
    r, rows = report(firmware_built)
    assert r.returncode == 0, r.stderr
    assert "== AVR ATmega328P" in r.stdout and "== Cortex-M0" in r.stdout
    roles = {row["role"] for row in rows}
    assert {x.lower() for x in spec.roles} <= roles and "baseline_tpsc" in roles
    for row in rows:
        if row["role"] != "baseline_tpsc":
            assert row["codec"]["data"] == 0 and row["codec"]["bss"] == 0, row
            assert row["codec"]["text"] > 0 and row["skeleton"]["text"] > 0, row


def test_codec_and_skeleton_stay_under_todays_ceilings(firmware_built):
    used = avr_codec_skeleton(report(firmware_built)[1])
    assert used["tpsc"] <= TPSC_CEILING, used
    assert all(used[r] <= SENSOR_CEILING for r in SENSORS), used
    assert all(n <= ROLE_CEILING for n in used.values()), used


@pytest.mark.xfail(strict=True, reason="issue 15 open: sensors at 1.2-1.4 KiB, TPSC 2.9x its baseline, SPU 2.3 KiB")
def test_issue_15_targets(firmware_built):
    """A sensor role in 1 KiB, the TPSC within 1.5x of the hand-written baseline, any role in 2 KiB.
    Strict: once the generated C gets there this passes, xfail fails, and the ceilings above move."""
    used = avr_codec_skeleton(report(firmware_built)[1])
    assert used["tpsc"] <= TPSC_TARGET
    assert all(used[r] <= SENSOR_TARGET for r in SENSORS)
    assert all(n <= ROLE_TARGET for n in used.values())


def test_make_size_prints_nanopb_beside_ours_and_the_baseline(firmware_built):
    make("nanopb")
    r, rows = report(firmware_built, "--nanopb", "tpsc usrc")
    assert r.returncode == 0, r.stderr
    nanopb = {row["role"]: row["codec"] for row in json.loads((firmware_built / "size.json").read_text())
              if row["target"] == "avr-nanopb"}
    assert set(nanopb) == {"tpsc", "usrc"}
    ours = avr_codec_skeleton(rows)
    lines = r.stdout.splitlines()
    start = next(i for i, l in enumerate(lines) if l.startswith("== AVR codec bytes"))
    line = next(l for l in lines[start:] if l.startswith("tpsc "))
    cols = line.split()
    # role, ours, ours msg_*.c, baseline, ours/baseline, nanopb, nanopb/ours
    base = next(row for row in rows if row["role"] == "baseline_tpsc" and row["target"] == "avr")
    assert int(cols[1]) == ours["tpsc"]
    assert int(cols[3]) == sum(base[p][k] for p in ("codec", "skeleton") for k in ("text", "data")) > 0
    assert int(cols[5]) == nanopb["tpsc"]["text"] + nanopb["tpsc"]["data"] > 0
    assert cols[4] == f"{ours['tpsc'] / int(cols[3]):.2f}x"


def test_stack_figures_cover_the_decode_paths(firmware_built):
    _, rows = report(firmware_built)
    for row in rows:
        st = row["stack"]
        assert 0 < st["parse"] < st["node"] and 0 < st["dispatch"] < st["node"], row
        assert not [n for n in row["notes"] if n.startswith(("unresolved", "recursion"))], row
    tpsc = next(r for r in rows if r["role"] == "tpsc" and r["target"] == "avr")
    assert tpsc["stack"]["node"] < 2048 // 4, "a TPSC should need well under a quarter of the 328P's RAM"
