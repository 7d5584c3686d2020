"""Issue 10, item 9: `arachnae check` refuses what it would silently clamp or ignore."""
from __future__ import annotations

import pytest

from tests.hostile.conftest import assert_one_line_error, snapshot

# (name, arguments after `check`, fragment of the one-line error)
CASES = [
    ("size above the slaves", ["arbitration", "--size", "99"], "--size 99: bus first (arbitration) has only"),
    ("size above for id_retry", ["id_retry", "--bus", "sensor", "--size", "50"], "--size 50: bus sensor (id_retry)"),
    ("size above for all", ["all", "--size", "40"], "--size 40: bus"),
    ("size zero", ["arbitration", "--size", "0"], "--size: must be at least 1"),
    ("size negative", ["arbitration", "--size", "-3"], "--size: must be at least 1"),
    ("size not a number", ["arbitration", "--size", "two"], "--size: not a number"),
    ("legs above six", ["post", "--legs", "7"], "--legs 7: the spec has 6 legs"),
    ("legs huge", ["post", "--legs", "9" * 30], "the spec has 6 legs"),
    ("legs on arbitration", ["arbitration", "--legs", "2"], "--legs does not apply to this model"),
    ("size on post", ["post", "--size", "2"], "--size does not apply to this model"),
    ("bus on post", ["post", "--bus", "first"], "--bus does not apply"),
    ("variant on id_retry", ["id_retry", "--variant", "seed"], "--variant does not apply"),
    ("scope on id_retry", ["id_retry", "--scope", "all"], "--scope does not apply"),
    ("no-symmetry on arbitration", ["arbitration", "--no-symmetry"], "--no-symmetry does not apply"),
    ("bus on all", ["all", "--bus", "first"], "--bus does not apply"),
    ("unknown bus", ["arbitration", "--bus", "nope"], "--bus nope: unknown bus"),
    ("polled bus", ["arbitration", "--bus", "leg"], "polled"),
    ("unknown model", ["nonsense"], "unknown model 'nonsense'"),
    ("hash-compact too narrow", ["id_retry", "--hash-compact", "8"], "must be 16 .. 64: 8"),
    ("two search modes", ["id_retry", "--bitstate", "20", "--hash-compact", "32"], "choose one search mode"),
    ("promela folder missing", ["post", "--legs", "1", "--promela", "NOWHERE"], "--promela NOWHERE: no such folder"),
    ("promela is a file", ["post", "--legs", "1", "--promela", "FILE"], "no such folder"),
]


@pytest.mark.parametrize("name, args, fragment", CASES, ids=[c[0] for c in CASES])
def test_check_refuses_in_one_line(cli, tmp_path, name, args, fragment):
    (tmp_path / "file.txt").write_text("mine")
    args = [str(tmp_path / "missing") if a == "NOWHERE" else str(tmp_path / "file.txt") if a == "FILE" else a
            for a in args]
    fragment = fragment.replace("NOWHERE", str(tmp_path / "missing"))
    before = snapshot(tmp_path)
    assert_one_line_error(cli("check", *args, "--quiet"), fragment)
    assert snapshot(tmp_path) == before


def test_an_unwritable_promela_folder_is_refused_before_the_run(cli, tmp_path, monkeypatch):
    import model_check.cli as mc

    def refuse(**_kw):
        raise PermissionError(13, "Permission denied")
    monkeypatch.setattr(mc.tempfile, "TemporaryFile", refuse)     # root may write anywhere: simulate EACCES
    assert_one_line_error(cli("check", "post", "--legs", "1", "--promela", str(tmp_path), "--quiet"),
                          f"--promela {tmp_path}: cannot write there (Permission denied)")
