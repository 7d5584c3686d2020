"""Issue 6.2 and 6.5: size per role and stack depth, from the linker maps and the call graph."""
from __future__ import annotations

import json
import subprocess
import sys

from tests.firmware.conftest import FIRMWARE


def report(build):
    r = subprocess.run([sys.executable, str(FIRMWARE / "size_report.py"), "--build", str(build)],
                       capture_output=True, text=True)
    return r, json.loads((build / "size.json").read_text())


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


def test_tpsc_codec_and_skeleton_fit_2_kib_of_avr_flash(firmware_built):
    _, rows = report(firmware_built)
    tpsc = next(r for r in rows if r["role"] == "tpsc" and r["target"] == "avr")
    used = sum(tpsc[p][k] for p in ("codec", "skeleton") for k in ("text", "data"))
    assert used <= 2048, f"TPSC codec + skeleton {used} bytes"


def test_stack_figures_cover_the_decode_paths(firmware_built):
    _, rows = report(firmware_built)
    for row in rows:
        st = row["stack"]
        assert 0 < st["parse"] < st["node"] and 0 < st["dispatch"] < st["node"], row
        assert not [n for n in row["notes"] if n.startswith(("unresolved", "recursion"))], row
    tpsc = next(r for r in rows if r["role"] == "tpsc" and r["target"] == "avr")
    assert tpsc["stack"]["node"] < 2048 // 4, "a TPSC should need well under a quarter of the 328P's RAM"
