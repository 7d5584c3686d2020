"""Counterexample replay (issue 11, part 2): the seed lasso starves a request on the real node code, the same
fault schedule under the spec's rule is served within the K the checker proves."""
from __future__ import annotations

import yaml

from model_check import replay
from model_check.engine import explore
from model_check.models import arbitration
from model_check.spec_adapter import arbitration as arb_params
from sim2d import runner
from tracecheck.bounds import bounds


def test_replay_writes_the_counterexample_as_scenarios(replay_dir, spec):
    seed = yaml.safe_load((replay_dir / "replay_arbitration_sensor_seed.yaml").read_text())
    fixed = yaml.safe_load((replay_dir / "replay_arbitration_sensor_spec.yaml").read_text())
    assert seed["arbitration"] == {"sensor": "seed"} and fixed["arbitration"] == {"sensor": "spec"}
    # arrivals at the same model tick, then the loop's collisions: forever (no until)
    # --size 2 keeps the first two slaves in the spec's rank order (declared priority: TPSC, IRRC)
    first_two = sorted(n.short for n in spec.requesters("sensor")[:2])
    requests = [f for f in seed["faults"] if "request" in f]
    assert sorted(f["request"] for f in requests) == first_two
    assert len({f["at"] for f in requests}) == 1
    collide = next(f for f in seed["faults"] if "collide" in f)
    assert collide["collide"] == first_two and "until" not in collide
    assert seed["faults"] == fixed["faults"]
    assert (replay_dir / "counterexample_sensor.json").exists()
    assert (replay_dir / "replay_arbitration_sensor_seed.yaml").read_text().startswith(f"# {replay.REPLAY_MARK}")


def test_replay_never_replaces_a_users_file(replay_dir, tmp_path):
    """issue 10.1: a file of the same name that --replay did not write stops it before it writes anything;
    its own earlier output is replaced (the command run twice into one folder)."""
    import subprocess
    import sys

    args = [sys.executable, "-m", "arachnae", "check", "arbitration", "--variant", "seed", "--bus", "sensor",
            "--size", "2", "--quiet", "--replay", str(tmp_path)]
    mine = tmp_path / "replay_arbitration_sensor_spec.yaml"
    mine.write_text("my own scenario\n")
    p = subprocess.run(args, capture_output=True, text=True, timeout=300)
    assert p.returncode == 1 and p.stderr.count("\n") == 1 and "was not written by --replay" in p.stderr, p.stderr
    assert sorted(x.name for x in tmp_path.iterdir()) == [mine.name] and mine.read_text() == "my own scenario\n"
    mine.unlink()
    for _ in range(2):
        p = subprocess.run(args, capture_output=True, text=True, timeout=300)
        assert p.returncode == 1 and "replay:" in p.stdout, p.stderr      # 1: the seed rule's counterexample
    assert sorted(x.name for x in tmp_path.iterdir()) == sorted(x.name for x in replay_dir.iterdir())


def test_seed_lasso_starves_a_request_in_the_simulator(replay_dir):
    out = runner.run(str(replay_dir / "replay_arbitration_sensor_seed.yaml"))
    p = out.result.metrics["protocol"]
    k = p["k_slots"]["sensor"]
    assert p["starved"] >= 1 and p["max_wait_slots"]["sensor"] > k, p
    assert p["violations"] == 0                  # a behaviour the seed variant's model allows
    assert not out.failed, out.failed


def test_same_schedule_under_the_spec_rule_recovers_within_k(replay_dir):
    out = runner.run(str(replay_dir / "replay_arbitration_sensor_spec.yaml"))
    p = out.result.metrics["protocol"]
    assert out.result.metrics["buses"]["sensor"]["collisions"] > 0     # the injected collision happened
    assert p["starved"] == 0 and p["violations"] == 0, p
    assert p["max_wait_slots"]["sensor"] <= p["k_slots"]["sensor"]
    assert not out.failed, out.failed


def test_k_comes_from_the_checker(spec):
    """The bound the validator holds requests to is the checker's K for that bus and its slaves."""
    res = explore(arbitration.build(arb_params(spec, "sensor"), "spec"), progress=False)
    assert bounds(spec)["sensor"].k_ticks == max(res.bounds.values())


def test_replay_of_a_model_that_holds_is_refused(spec, tmp_path):
    import pytest
    from arachnae.errors import UserError

    res = explore(arbitration.build(arb_params(spec, "sensor"), "spec", 2), progress=False)
    with pytest.raises(UserError, match="holds"):
        replay.write(res, str(tmp_path / "r"), "arachnae check arbitration")
    assert not (tmp_path / "r").exists()
