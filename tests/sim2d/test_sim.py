"""The whole robot: 39 node processes exchanging bytes over the simulated buses."""
from __future__ import annotations


from sim2d.scenario import load_scenario
from sim2d.sim import Simulation

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
    names = [sim.codec.decode(f.heard).name for f in r.frames if f.heard and sim.codec.decode(f.heard)]
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
    text = "duration: 25\n" + ROOM % "" + "obstacles: [{polygon: [[2.0, 1], [2.2, 1], [2.2, 3], [2.0, 3]], height: 0.3}]\n"
    _, r = run(write, spec, text)
    m = r.metrics
    assert m["reaction_latencies_s"], "the obstacle was never sensed"
    assert m["max_reaction_s"] <= 1.0                  # seed 5.2
    assert m["collisions"] == 0 and r.robot.pose[0] < 2.0
