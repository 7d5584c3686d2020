"""`arachnae check` / `arachnae timing` exit codes and the counterexample formats."""
import json

from arachnae.cli import main
from model_check import msc
from model_check import spec_adapter as sa
from model_check.engine import explore
from model_check.models import arbitration


def test_seed_variant_exits_1_with_mermaid_lasso(capsys):
    rc = main(["check", "arbitration", "--variant", "seed", "--bus", "sensor", "--size", "2", "--quiet"])
    out = capsys.readouterr().out
    assert rc == 1
    assert "VIOLATED liveness" in out and "sequenceDiagram" in out and "loop repeats forever" in out


def test_spec_variant_with_window_exits_0_and_prints_K(capsys):
    rc = main(["check", "arbitration", "--scope", "all", "--bus", "sensor", "--quiet"])
    out = capsys.readouterr().out
    assert rc == 0
    assert "ALL PROPERTIES HOLD" in out and "K = " in out and "never fired: none" in out


def test_json_output_carries_counts_and_counterexample(capsys):
    rc = main(["check", "arbitration", "--variant", "seed", "--bus", "first", "--size", "2", "--json", "--quiet"])
    data = json.loads(capsys.readouterr().out)
    assert rc == 1 and data[0]["holds"] is False
    assert data[0]["states"] > 0 and data[0]["transitions"] >= data[0]["states"] - 1
    cx = data[0]["counterexample"]
    assert cx["kind"] == "liveness" and cx["loop_start"] is not None
    assert any(e["message"].startswith("XMIT_REQ") or "collide" in e["message"]
               for s in cx["steps"] for e in s.get("events", []))


def test_user_mistakes_are_one_line_errors(capsys):
    assert main(["check", "nonsense"]) == 1
    assert main(["check", "arbitration", "--bus", "leg"]) == 1     # polled bus: nothing to arbitrate
    assert main(["check", "post", "--variant", "seed"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 3 and all("Traceback" not in line for line in err)


def test_timing_reports_the_scan_requirement_as_unmet(capsys):
    assert main(["timing", "--scope", "all"]) == 0
    out = capsys.readouterr().out
    assert "360 deg ultrasonic scan" in out and "FAILS" in out
    assert "whisker contact to STOP" in out


def test_mermaid_names_every_message_of_the_trace(spec):
    res = explore(arbitration.build(sa.arbitration(spec, "sensor", "colliders"), "spec", 3), progress=False)
    text = msc.to_mermaid(res, res.violation)
    steps = msc.to_json(res, res.violation)["steps"]
    for s in steps:
        for e in s.get("events", []):
            assert e["message"] in text
    assert text.startswith("sequenceDiagram")
