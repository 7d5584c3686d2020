"""Issue 10: `timing` and `check` on a spec that renamed what the models use.

A bus name is the user's choice, so the models find their buses from the spec (arbitration kind, who
receives HEAD_STEP); the seed's message names (ID_REQ, ID_ACK) are what the models are proofs about, so a
spec without them gets one line naming the file, never a KeyError traceback.
"""
from __future__ import annotations

import pytest

from model_check.checks import MODELS
from tests.hostile.spec_harness import M, cli, rename, spec_copy


@pytest.fixture(scope="module")
def renamed_bus(tmp_path_factory):
    spec = spec_copy(tmp_path_factory.mktemp("bus"))
    rename(spec, "sensor", "sens")
    return spec


@pytest.fixture(scope="module")
def renamed_message(tmp_path_factory):
    spec = spec_copy(tmp_path_factory.mktemp("msg"))
    rename(spec, "ID_REQ", "IDENT_REQ")
    return spec


def test_timing_follows_a_renamed_bus(renamed_bus):
    run = cli("timing", "--spec", renamed_bus)
    assert run.returncode == 0, run.stderr
    assert "sensor-bus frames" in run.stdout and "whisker contact to STOP" in run.stdout


@pytest.mark.parametrize("args", [["id_retry", "--size", "2"], ["reaction", "--size", "1"],
                                  ["arbitration", "--size", "2"]])
def test_check_follows_a_renamed_bus(renamed_bus, args):
    run = cli("check", *args, "--spec", renamed_bus)
    assert run.returncode == 0, run.stderr
    assert "Traceback" not in run.stderr
    assert "sens" in run.stdout and "ALL PROPERTIES HOLD" in run.stdout


@pytest.mark.parametrize("command", [["timing"], ["check", "id_retry", "--size", "2", "--quiet"]])
def test_a_missing_seed_message_is_one_line(renamed_message, command):
    run = cli(*command, "--spec", renamed_message)
    lines = run.stderr.strip().splitlines()
    assert run.returncode != 0 and len(lines) == 1, run.stderr
    assert lines[0].startswith(str(renamed_message / M)) and "'ID_REQ'" in lines[0]


@pytest.mark.parametrize("model", MODELS)
def test_every_model_is_a_check_subcommand(model):
    """Each model `check all` proves can be run on its own (`check reaction` was refused as unknown)."""
    args = {"arbitration": ["--size", "2"], "id_retry": ["--size", "2"], "post": ["--legs", "1"],
            "reaction": ["--size", "1"]}[model]
    run = cli("check", model, *args, "--quiet")
    assert run.returncode == 0 and "unknown model" not in run.stderr, run.stderr
