"""A message no role's implementation sends or handles is a warning that names it; warnings never fail
`spec check`, errors do (issue 10, item 10); a code carried inside another message is used when that one is."""
from __future__ import annotations

from pathlib import Path

from codegen.usage import carriers, unused_messages
from tests.hostile.spec_harness import M, REPO, add_message, cli, snapshot, spec_copy


def test_shipped_spec_passes_without_warnings() -> None:
    """The whisker codes OBJ_LEFT/RIGHT/BOTH travel as TPSC_CONTACT bits in XMIT_DATA_TPSC (seed 3.2.12): used."""
    run = cli("spec", "check")
    assert run.returncode == 0 and run.stdout.startswith("spec ok"), run.stderr
    assert run.stderr == ""


def test_a_code_carried_inside_another_message_is_used_when_its_carrier_is(tmp_path: Path, spec) -> None:
    assert carriers(spec) == {"OBJ_LEFT": "XMIT_DATA_TPSC", "OBJ_RIGHT": "XMIT_DATA_TPSC", "OBJ_BOTH": "XMIT_DATA_TPSC"}
    (tmp_path / "behaviours").mkdir()
    (tmp_path / "behaviours" / "x.py").write_text("self.send(spu, M.XmitDataTpsc(contact=0x10))\n")
    assert not {"OBJ_LEFT", "OBJ_RIGHT", "OBJ_BOTH", "XMIT_DATA_TPSC"} & set(unused_messages(spec, tmp_path))
    (tmp_path / "behaviours" / "x.py").write_text("pass\n")          # carrier unused: the codes are named too
    assert {"OBJ_LEFT", "OBJ_RIGHT", "OBJ_BOTH", "XMIT_DATA_TPSC"} <= set(unused_messages(spec, tmp_path))


def test_new_unused_message_is_named_and_still_passes(tmp_path: Path) -> None:
    spec_dir = spec_copy(tmp_path)
    add_message(spec_dir, "WHISKER_TWITCH")
    before = snapshot(spec_dir)
    run = cli("spec", "check", "--spec", spec_dir)
    assert run.returncode == 0, run.stderr
    assert any(": warning: WHISKER_TWITCH is declared (from TPSC to SPU)" in line for line in run.stderr.splitlines())
    assert snapshot(spec_dir) == before


def test_a_reference_in_any_implementation_counts(tmp_path: Path, spec) -> None:
    for top, text in (("behaviours", "self.send(spu, M.ObjLeft())\n"), ("firmware", "arachnae_obj_right_build(&f);\n"),
                      ("console", "def on_obj_both(self, src, msg):\n")):
        (tmp_path / top).mkdir()
        (tmp_path / top / ("x.c" if top == "firmware" else "x.py")).write_text(text)
    unused = unused_messages(spec, tmp_path)
    assert not {"OBJ_LEFT", "OBJ_RIGHT", "OBJ_BOTH"} & set(unused)
    assert "MOVE" in unused and len(unused) == len(spec.messages) - 3


def test_errors_still_fail_alongside_warnings(tmp_path: Path) -> None:
    spec_dir = spec_copy(tmp_path)
    add_message(spec_dir, "WHISKER_TWITCH", 'doc: "x", broadcast: true')
    run = cli("spec", "check", "--spec", spec_dir)
    assert run.returncode == 1 and "only bus masters may broadcast, TPSC masters no bus" in run.stderr, run.stderr
