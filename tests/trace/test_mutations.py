"""A mutation of the node code alone (never the spec or the models) makes the trace validator fail, naming
the first offending frame by time and bus (issue 11, part 1): the proofs reach the code that runs."""
from __future__ import annotations

import re
from arachnae_proto.network import POST

from arachnae_proto import messages as M
from behaviours import mcp, sensors
from behaviours.runtime import BusTiming, Runtime
from model_check.spec_adapter import load
from sim2d import hardware, runner
from tracecheck.trace import COLUMNS, parse_lines, trace_lines
from tracecheck.validate import validate

FIRST = re.compile(r"^(\d+\.\d{6}) s bus (\w+) \(trace line (\d+)\): (\w+): ")


def first(outcome) -> tuple[float, str, str]:
    p = outcome.result.metrics["protocol"]
    assert p["violations"] > 0, p
    m = FIRST.match(p["first"])
    assert m, p["first"]
    return float(m.group(1)), m.group(2), m.group(4)


def mutate_timing(monkeypatch, **changes) -> None:
    init = BusTiming.__init__

    def mutated(self, bus):
        init(self, bus)
        for k, v in changes.items():
            setattr(self, k, v)
    monkeypatch.setattr(BusTiming, "__init__", mutated)


def test_unmutated_code_has_no_violation(missing_scenario):
    out = runner.run(str(missing_scenario))
    p = out.result.metrics["protocol"]
    assert p["violations"] == 0, p["first"]
    assert p["checked"]["id_req"] > 0 and p["checked"]["post_verdict"] == 1
    assert not out.failed


def test_backoff_rank_mutation_is_caught(monkeypatch, replay_dir):
    rank = Runtime.rank
    monkeypatch.setattr(Runtime, "rank", lambda self, bus: len(self.net.requesters[bus]) - 1 - rank(self, bus))
    t, bus, rule = first(runner.run(str(replay_dir / "replay_arbitration_sensor_spec.yaml")))
    assert (bus, rule) == ("sensor", "backoff_slot") and t > 3.0


def test_retry_count_mutation_is_caught(monkeypatch, missing_scenario):
    mutate_timing(monkeypatch, id_retries=0)
    t, bus, rule = first(runner.run(str(missing_scenario)))
    assert rule == "id_retry" and bus in ("sensor", "leg") and t < 2.0


def test_timeout_mutation_is_caught(monkeypatch, missing_scenario):
    mutate_timing(monkeypatch, timeout_s=0.004)
    t, bus, rule = first(runner.run(str(missing_scenario)))
    assert rule == "id_timeout" and t < 1.0


def test_post_quorum_mutation_is_caught(monkeypatch, missing_scenario):
    verdict = mcp.verdict

    def six_legs(missing, post=POST):
        return verdict(missing, post._replace(quorums=tuple(q._replace(min_complete=q.min_complete + 1)
                                                            for q in post.quorums)))
    monkeypatch.setattr(mcp, "verdict", six_legs)
    out = runner.run(str(missing_scenario))
    t, bus, rule = first(out)
    assert (bus, rule) == ("debug", "post_verdict")
    assert "says HALTED" in out.result.metrics["protocol"]["first"] and "says DEGRADED" in \
        out.result.metrics["protocol"]["first"]


def test_reflex_rate_limit_is_checked_and_its_mutation_is_caught(monkeypatch, missing_scenario):
    """spec reflexes.min_interval_ms (250 ms), which bounds the arbitration model's reflex lead: a whisker whose
    contact changes every 50 ms makes the TPSC raise as often as its limit lets it. The real code passes, with
    the TPSC's raise notes checked; a 200 ms limit in the behaviour alone is caught at the second raise; a trace
    without the notes (a capture) says the check was skipped."""
    monkeypatch.setattr(hardware.NodeHardware, "whiskers",
                        lambda self: (True, int(self.sched.now / 0.05) % 2 == 0))
    out = runner.run(str(missing_scenario))
    p = out.result.metrics["protocol"]
    assert p["violations"] == 0, p["first"]
    assert p["checked"]["reflex_rate"] >= 5 and p["skipped"] == {}
    lines = ["\t".join(COLUMNS)] + trace_lines(out.result.frames)          # the frames, no debug rows
    bare = validate(parse_lines(lines, "capture.tsv"), load()).metrics()
    assert "TPSC" in bare["skipped"]["reflex_rate"] and "not checked" in bare["skipped"]["reflex_rate"]
    start = sensors.TPSC.start

    def faster(self):
        start(self)
        self.min_interval = 0.2
    monkeypatch.setattr(sensors.TPSC, "start", faster)
    mutated = runner.run(str(missing_scenario))
    t, bus, rule = first(mutated)
    assert (bus, rule) == ("debug", "reflex_rate") and "200.0 ms after the last" in \
        mutated.result.metrics["protocol"]["first"]


def test_corrupt_id_frames_pass_and_a_master_taking_one_for_an_answer_is_caught(monkeypatch, corrupt_id_scenario):
    """The id_retry model counts a corrupt ID_REQ or ID_ACK as lost (its docstring says why); the validator's
    id_retry / id_timeout rules hold the real exchange to it: the real code passes with ID frames heard corrupt,
    and a master that takes a corrupt frame heard while it waits for an ID_ACK as the answer (no CRC check)
    is caught at the first one, before the POST verdict it falsifies."""
    out = runner.run(str(corrupt_id_scenario))
    p = out.result.metrics["protocol"]
    assert out.result.metrics["buses"]["sensor"]["corrupted"] > 0
    assert p["violations"] == 0, p["first"]
    on_codec_error = Runtime.on_codec_error

    def no_crc_check(self, bus, err):
        on_codec_error(self, bus, err)
        link = self.links.get(bus)
        req = link.current if link is not None else None
        if req is not None and req.sent and M.IdAck in req.expect:
            link.current = None
            req.on_reply(req.dst, M.IdAck(address=req.dst))
            self._next(link)
    monkeypatch.setattr(Runtime, "on_codec_error", no_crc_check)
    t, bus, rule = first(runner.run(str(corrupt_id_scenario)))
    assert (bus, rule) == ("sensor", "id_retry") and t < 2.0
