"""Subsumption library (docs/decisions.md D8, seed 5.2): suppression, inhibition, the control trace, the NP3 network."""
from __future__ import annotations

import math

import pytest

from arachnae_proto.enums import MovCmd
from behaviours.np3_layers import AVOIDANCE, REFLEXES, TASK
from behaviours import tuning as T
from behaviours.np3_layers import np3_network
from behaviours.subsumption import NONE_LAYER, FunctionModule, Network


class FakeClock:
    def __init__(self, t: float = 0.0) -> None:
        self.t = t

    def __call__(self) -> float:
        return self.t


def run(net: Network, clock: FakeClock, until: float, dt: float = 0.1, each=None) -> list[tuple[float, object]]:
    """Step the network every dt up to `until` (exclusive); returns (time, move) after each step."""
    out = []
    while clock.t < until - 1e-9:
        if each:
            each(clock.t)
        out.append((round(clock.t, 6), net.step()["move"]))
        clock.t = round(clock.t + dt, 6)
    return out


def two_layer_net(clock: FakeClock, kind: str, hold_s: float) -> Network:
    """A 'low' module always sending 'low'; a 'high' one sending 'high' while sensor `go` is set."""
    net = Network(clock)
    net.add(FunctionModule("low", "task", (), ("move",), lambda i, now: {"move": "low"}))
    net.add(FunctionModule("high", "reflexes", ("go",), ("move",),
                           lambda i, now: {"move": "high" if i["go"] else None}))
    net.wire("sensor.go", "high.go")
    net.wire("low.move", net.actuator("move"))
    if kind == "suppress":
        net.suppress("high.move", "actuator.move", hold_s)
    else:
        net.inhibit("high.move", "low.move", hold_s)
    net.sense(go=False)
    return net


def test_suppression_replaces_the_input_and_holds_for_its_time_constant():
    clock = FakeClock()
    net = two_layer_net(clock, "suppress", hold_s=1.0)
    log = run(net, clock, 3.0, each=lambda t: net.sense(go=0.5 <= t < 1.0))
    moves = dict(log)
    assert moves[0.4] == "low"
    assert moves[0.5] == "high"                     # replaced in the same step
    # last 'high' message at 0.9 s: the wire stays cut until 1.9 s, so the actuator keeps 'high'
    assert all(moves[t] == "high" for t in moves if 0.5 <= t < 1.9)
    assert moves[1.9] == "low" and moves[2.5] == "low"   # released after the time constant


def test_inhibition_blocks_the_lower_output_without_replacing_it():
    clock = FakeClock()
    net = two_layer_net(clock, "inhibit", hold_s=0.5)
    delivered = {}
    for t10 in range(30):
        clock.t = t10 / 10
        net.sense(go=10 <= t10 < 15)                 # 'high' speaks from 1.0 to 1.4 s
        net.step()
        delivered[clock.t] = net.delivered["move"]
    blocked = sorted(t for t, port in delivered.items() if port is None)
    # 'low' is blocked from the first 'high' message until 0.5 s after the last one (1.4 + 0.5)
    assert blocked == pytest.approx([t10 / 10 for t10 in range(10, 19)])
    assert delivered[0.9] == delivered[1.9] == "low.move"
    # the inhibitor's own message never reaches the actuator: the value held is still 'low'
    assert net.actuators["move"] == "low"
    assert [iv.module for iv in net.trace("move").intervals()] == ["low"]


def test_trace_intervals_cover_the_run_and_summary_sums_per_layer():
    clock = FakeClock(2.0)
    net = np3_network(clock, task="forward")
    net.sense(battery_low=False, tilt=(0.0, 0.0), ir=(None, None, None))

    def world(t: float) -> None:
        if abs(t - 5.0) < 1e-9:                      # a head-on whisker contact (both sides, seed 3.2.12)
            net.sense(whisker=(1, True, True, t))
        net.sense(ir=(None, 0.07, None) if 15.0 <= t < 15.3 else (None, None, None))

    run(net, clock, 30.0, each=world)
    trace = net.trace("move")
    ivs = trace.intervals(until=30.0)
    assert ivs[0].start == pytest.approx(2.0) and ivs[-1].end == pytest.approx(30.0)
    for a, b in zip(ivs, ivs[1:]):
        assert a.end == pytest.approx(b.start)      # no gaps, no overlaps
    assert sum(iv.duration for iv in ivs) == pytest.approx(28.0)
    summary = trace.summary(until=30.0)
    assert sum(summary.values()) == pytest.approx(28.0)
    assert set(summary) == {TASK, REFLEXES, AVOIDANCE}
    # both whiskers, IR clear: a surface square ahead: back off, turn until it is contact_clear_deg behind the
    # side, plus the suppressor's hold of 0.5 s
    turn_s = (90 + T.NP3_CONTACT_CLEAR_DEG) / T.NP3_DR_TURN_DEG_S
    assert summary[REFLEXES] == pytest.approx(T.NP3_CONTACT_BACK_S + turn_s + 0.5 - 0.1, abs=0.11)
    assert trace.switches(until=30.0) == 4          # task, reflexes, task, avoidance, task
    assert NONE_LAYER not in summary                # the task drives from the very first step


def test_a_reflex_pre_empts_the_task_in_the_same_step():
    clock = FakeClock()
    net = np3_network(clock, task="forward")
    assert net.step()["move"] == MovCmd.FORWARD
    clock.t = 0.1
    net.sense(whisker=(1, True, True, 0.1))          # seed 3.2.12: OBJ_BOTH
    assert net.step()["move"] == MovCmd.BACKWARD     # 5.2: reaction well within 1 s: this very step
    assert net.trace("move").current == (0.1, REFLEXES, "contact")   # (since, layer, module)
    clock.t = 1.8                                    # after backing off it turns away
    assert net.step()["move"] in (MovCmd.TURN_LEFT, MovCmd.TURN_RIGHT)
    clock.t = 7.0
    net.sense(whisker=(2, True, False, 7.0))         # OBJ_LEFT alone: turn right at once, no backing off
    assert net.step()["move"] == MovCmd.TURN_RIGHT


def test_a_stale_whisker_event_starts_nothing():
    clock = FakeClock(3.0)
    net = np3_network(clock, task="forward")
    net.sense(whisker=(1, True, True, 1.0))          # delivered 2 s ago, while another reflex held the MMC
    assert net.step()["move"] == MovCmd.FORWARD


def test_stop_reflexes_win_over_backing_off():
    clock = FakeClock()
    net = np3_network(clock, task="forward")
    net.sense(whisker=(1, True, True, 0.0), battery_low=True)   # contact and under-voltage at once (3.2.17)
    assert net.step()["move"] == MovCmd.STOP
    net.sense(ir_fault=True)
    clock.t = 0.3
    assert net.step()["move"] == MovCmd.STOP


def test_avoidance_turns_away_from_the_nearer_side_and_task_resumes():
    clock = FakeClock()
    net = np3_network(clock, task="forward")
    net.sense(ir=(0.05, None, None))                 # obstacle on the left, not yet a contact
    assert net.step()["move"] == MovCmd.TURN_RIGHT
    net.sense(ir=(None, None, None))
    clock.t = 0.1
    log = dict(run(net, clock, 5.0))
    resumed = min(t for t, v in log.items() if v == MovCmd.FORWARD)
    assert resumed == pytest.approx(0.8 + 0.3, abs=0.11)   # turn plan, then the hold releases


def test_avoidance_on_the_echo_memory_keeps_turning_the_way_it_started():
    """issue 17 (scenarios/sonar_first.yaml): a wall ahead seen by the sonar only; after the first turn the memory
    shows the side turned to as seen (a wall) and the other as unknown, and choosing again turned the robot back."""
    clock = FakeClock()
    net = np3_network(clock, task="forward")
    wall_right = tuple((0.3, y / 10, 0.0, 0.0) for y in range(-6, 1))       # a wall 0.3 m ahead, right of the axis
    net.sense(pose=(0.0, 0.0, 0.0), echoes=wall_right)
    assert net.step()["move"] == MovCmd.TURN_LEFT                             # the clearer side
    wall_left = tuple((0.3, y / 10, 0.0, 0.0) for y in range(0, 7))          # now only its other end seen, ahead
    net.sense(echoes=wall_left)
    clock.t = 0.9                                                             # the next turn: the same way
    assert net.step()["move"] == MovCmd.TURN_LEFT
    net.sense(echoes=())
    clock.t = 2.5
    assert net.step()["move"] == MovCmd.FORWARD                               # clear: the task again
    net.sense(echoes=wall_left)
    clock.t = 10.0                                                            # a new obstacle long after: chosen anew
    assert net.step()["move"] == MovCmd.TURN_RIGHT


def wall(normal_deg: float, dist_m: float) -> tuple[tuple[float, float, float, float], ...]:
    """Echo points (body frame, seen straight on) of a straight wall whose normal from the body is at normal_deg."""
    n = math.radians(normal_deg)
    return tuple((dist_m * math.cos(n) - s / 20 * math.sin(n), dist_m * math.sin(n) + s / 20 * math.cos(n), 0.0, 0.0)
                 for s in range(-8, 9))


def test_avoidance_turns_away_from_the_side_the_surface_in_its_way_faces_it_from():
    """issue 17, corridor_narrow seed 2: the robot had turned right away from the left-hand wall; the next echoes
    in its way lay on the right-hand wall, facing it from the right, and avoidance kept turning right into it
    (the body ended across the corridor, its rear swung into the other wall)."""
    clock = FakeClock()
    net = np3_network(clock, task="forward")
    net.sense(pose=(0.0, 0.0, 0.0), echoes=wall(60.0, 0.25))       # the left wall, met at 30 deg
    assert net.step()["move"] == MovCmd.TURN_RIGHT
    net.sense(echoes=wall(-60.0, 0.25))                              # within the keep time: the right wall
    clock.t = 0.9
    assert net.step()["move"] == MovCmd.TURN_LEFT
    net.sense(echoes=((0.25, 0.0, 0.0, 0.0),) * 3)                   # one IR point, read again and again: square
    clock.t = 1.8                                                    # on, the side turned last is kept
    assert net.step()["move"] == MovCmd.TURN_LEFT


def test_wiring_table_lists_every_declared_connection():
    net = np3_network(FakeClock(), task="explore")
    table = net.wiring_table()
    lines = table.splitlines()
    assert lines[0].split() == ["kind", "from", "to", "hold", "s"]
    assert any(l.split()[:3] == ["wire", "task.move", "actuator.move"] for l in lines)
    assert any(l.split() == ["suppress", "avoid.move", "actuator.move", "0.3"] for l in lines)
    assert sum(1 for l in lines if l.startswith("suppress")) == 2 + 8   # orient, avoidance + eight reflexes (guard, pinned)
    assert len(lines) == 2 + len(net.wires) + len(net.nodes)


def test_cycles_and_bad_ports_are_rejected():
    net = Network(FakeClock())
    net.add(FunctionModule("a", "x", ("i",), ("o",), lambda i, now: {"o": 1}))
    net.add(FunctionModule("b", "x", ("i",), ("o",), lambda i, now: {"o": 1}))
    with pytest.raises(ValueError):
        net.wire("a.nope", "b.i")
    net.wire("a.o", "b.i")
    net.wire("b.o", "a.i")
    with pytest.raises(ValueError, match="cycle"):
        net.step()


def test_explore_without_a_goal_wanders_with_growing_turns():
    clock = FakeClock()
    net = np3_network(clock, task="explore")
    log = run(net, clock, 45.0)
    turns = [t for t, v in log if v in (MovCmd.TURN_LEFT, MovCmd.TURN_RIGHT)]
    assert turns and math.isclose(turns[0], 12.0, abs_tol=1e-6)     # NP3_EXPLORE_WANDER_S
    assert dict(log)[12.0] == MovCmd.TURN_LEFT and dict(log)[12.0 + 4.8 + 12.0] == MovCmd.TURN_RIGHT


def test_explore_steers_for_the_goal():
    clock = FakeClock()
    net = np3_network(clock, task="explore")
    net.sense(pose=(0.0, 0.0, 0.0), goal=(0.0, 2.0))     # 90 degrees to the left
    assert net.step()["move"] == MovCmd.TURN_LEFT
    clock.t = 0.1
    net.sense(pose=(0.0, 0.0, math.radians(80)))
    assert net.step()["move"] == MovCmd.FORWARD
