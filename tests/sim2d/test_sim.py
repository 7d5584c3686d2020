"""The whole robot: 39 nodes (generated skeleton + behaviour) exchanging bytes over the simulated buses."""
from __future__ import annotations

from pathlib import Path

from arachnae_proto import CodecError
from arachnae_proto.frame import parse
from arachnae_proto.skeletons import skeleton_class

from sim2d.runner import run as run_file
from sim2d.scenario import load_scenario
from sim2d.sim import Simulation
from tracecheck.trace import trace_lines

ROOT = Path(__file__).resolve().parents[2]

ROOM = "arena: {size: [6, 4]}\nrobot: {pose: [1, 2, 0]%s}\n"


def run(write, spec, text, seed=None):
    sc = load_scenario(write("s.yaml", text), spec)
    if seed is not None:
        sc = sc.with_seed(seed)
    sim = Simulation(sc, spec)
    return sim, sim.run()


def test_same_seed_same_trace_other_seed_other_trace(write, spec):
    text = "duration: 6\n" + ROOM % "" + "faults: [{at: 2, until: 6, bus: leg, loss: 0.2}]\n"
    _, a = run(write, spec, text, 5)
    _, b = run(write, spec, text, 5)
    _, c = run(write, spec, text, 6)
    assert a.trace_hash == b.trace_hash and a.metrics == b.metrics
    assert a.trace_hash != c.trace_hash


def test_post_and_walk_end_to_end(write, spec):
    sim, r = run(write, spec, "duration: 12\n" + ROOM % "")
    m = r.metrics
    assert m["post"]["verdict"] == "OPERATIONAL" and m["post"]["time_s"] < 3
    names = {parse(f.heard).message.NAME for f in r.frames if f.heard is not None}
    for needed in ("ID_REQ", "ID_ACK", "POST_QUERY", "POST_REPORT", "XMIT_REQ", "XMIT_GRANT", "MOVE",
                   "MOVE_RELAYED", "LEG_TARGET", "JOINT_TARGET", "XMIT_DATA_USRC", "XMIT_DATA_IRRC", "DATA"):
        assert needed in names, needed
    x0 = r.poses[0][1]
    assert 0.5 < r.robot.pose[0] - x0 < 1.2          # walking after POST at ~10 cm/s
    # every frame on every bus is bytes of the spec's frame layout
    assert all(f.bus in spec.buses for f in r.frames)


def test_required_node_absent_halts_and_robot_never_moves(write, spec):
    _, r = run(write, spec, "duration: 8\n" + ROOM % ", absent: [USRC]")
    assert r.metrics["post"]["verdict"] == "HALTED"
    assert "USRC missing (required)" in r.metrics["post"]["reasons"]
    assert r.metrics["distance_walked_m"] == 0.0


def test_one_leg_missing_is_degraded_and_still_walks(write, spec):
    _, r = run(write, spec, "duration: 15\n" + ROOM % ", absent: ['JAC(2,3)']")
    assert r.metrics["post"]["verdict"] == "DEGRADED"
    assert r.metrics["post"]["missing"] == ["JAC(2,3)"]
    assert r.metrics["distance_walked_m"] > 0.1     # wave gait on five legs


def test_two_legs_missing_halts(write, spec):
    _, r = run(write, spec, "duration: 5\n" + ROOM % ", absent: ['LCP(1)', 'JAC(4,1)']")
    assert r.metrics["post"]["verdict"] == "HALTED"
    assert any("legs: 4 of 6" in s for s in r.metrics["post"]["reasons"])


def test_killed_node_goes_silent(write, spec):
    _, r = run(write, spec, "duration: 8\n" + ROOM % "" + "faults: [{at: 4, kill: IRRC}]\n")
    sent_after = [f for f in r.frames if f.sender == "IRRC" and f.start > 4.0]
    assert r.metrics["post"]["verdict"] == "OPERATIONAL" and sent_after == []
    assert any(f.sender == "IRRC" for f in r.frames)


def test_whisker_contact_is_answered_within_a_second(write, spec):
    # a post off the body axis, lower than the sonar head and beside the IR beams: only the left whisker finds it
    text = "duration: 20\n" + ROOM % "" + "obstacles: [{polygon: [[1.8, 2.1], [1.84, 2.1], [1.84, 2.14], [1.8, 2.14]], " \
        "height: 0.1}]\n"
    _, r = run(write, spec, text)
    m = r.metrics
    assert m["notes"]["stimulus"]["count"] >= 1 and m["reaction_latencies_s"], "the post was never touched"
    assert m["max_reaction_s"] <= 1.0                  # seed 5.2
    assert m["nodes"]["NP3"]["takeovers"]["contact"] >= 1
    assert m["collisions"] == 0


def test_every_node_is_its_generated_skeleton(write, spec):
    sim, _ = run(write, spec, "duration: 0.1\n" + ROOM % "")
    assert len(sim.nodes) == len(spec.nodes) == 39
    for n in spec.nodes:
        assert isinstance(sim.nodes[n.short], skeleton_class(n.role)), n.short


def test_scenario_trace_is_bytes_the_generated_codec_parses(spec):
    """issue 4: nodes exchange BYTES through the generated codec. Same seed -> same trace: this scenario run twice
    is tests/sim2d/test_cli.py's test_same_seed_prints_the_same_hash_and_metrics_cover_issue_4 (byte-identical
    trace.tsv), and test_same_seed_same_trace_other_seed_other_trace here (CHOICE: a second 45 s run for the
    same assertion was merged into those)."""
    path = ROOT / "scenarios" / "frame_loss.yaml"
    a = run_file(str(path), seed=3, spec=spec).result
    assert len(a.frames) > 1000
    corrupt = 0
    for f in a.frames:
        assert type(f.sent) is bytes and (f.heard is None or type(f.heard) is bytes)
        sent = parse(f.sent)                         # what the sender's skeleton framed
        assert sent.src == spec.node(f.sender).address
        if f.heard is not None and f.heard != f.sent:
            corrupt += 1
            try:
                parse(f.heard)
            except CodecError:
                continue
            raise AssertionError(f"a corrupted frame passed the CRC: {f}")
    assert corrupt > 0                               # the scenario corrupts frames on the first bus
    lines = trace_lines(a.frames)
    bad = [ln for ln in lines if "\t<" in ln]
    assert len(bad) == corrupt                       # the trace shows the codec's reason for exactly those
    assert all(ln.split("\t")[6].split()[0] == parse(bytes.fromhex(ln.split("\t")[7])).message.NAME
               for ln in lines if "\t<" not in ln)
