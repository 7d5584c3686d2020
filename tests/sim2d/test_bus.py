from __future__ import annotations

import random

import pytest

from sim2d.bus import Bus, Fault
from sim2d.events import Scheduler


def make(baud=9600, turnaround=500e-6):
    sched = Scheduler()
    trace = []
    bus = Bus("b", sched, baud, 10, turnaround, random.Random(1), trace.append)
    got: dict[str, list] = {}
    echoes: dict[str, list] = {}

    def port(name):
        got[name], echoes[name] = [], []
        return bus.attach(name, lambda b, t, d: got[name].append((t, d)),
                          lambda b, t, sent, heard: echoes[name].append((t, sent, heard)))
    return sched, bus, port, got, echoes, trace


def test_frame_takes_its_time_on_the_wire_and_everyone_hears_it():
    sched, bus, port, got, echoes, _ = make()
    a, b, c = port("a"), port("b"), port("c")
    a.send(b"\x01\x02\x03\x04\x05\x06")
    sched.run_until(1.0)
    t_end = 6 * 10 / 9600
    assert got["b"] == [(pytest.approx(t_end), b"\x01\x02\x03\x04\x05\x06")] == got["c"]
    assert got["a"] == [] and echoes["a"][0][1] == echoes["a"][0][2]      # the sender hears its echo only
    assert bus.stats.busy_s == pytest.approx(t_end)


def test_half_duplex_second_sender_waits_for_idle_plus_turnaround():
    sched, bus, port, got, _, trace = make()
    a, b, c = port("a"), port("b"), port("c")
    a.send(b"\xaa" * 10)
    sched.at(0.002, b.send, b"\xbb" * 4)      # line busy: carrier sense defers it
    sched.run_until(1.0)
    first_end = 10 * 10 / 9600
    assert [e.sender for e in trace] == ["a", "b"]
    assert trace[1].start == pytest.approx(first_end + 500e-6)
    assert bus.stats.collisions == 0


def test_a_frame_reported_late_is_carrier_judged_when_it_was_driven():
    """firmware/sil_bridge.py hands a firmware frame over up to a sync period late: one driven before the
    other frame's carrier could be sensed collides with it, as on the wire; one driven later still waits."""
    sched, bus, port, _got, _, trace = make()
    a, b, c = port("a"), port("b"), port("c")
    a.send(b"\xaa" * 10)
    sched.at(0.002, b.send, b"\xbb" * 4, 0.0)          # driven at 0: with a's start bit, not after it
    sched.at(0.003, c.send, b"\xcc" * 4, 0.002)        # driven 2 ms into a's frame: carrier sensed
    sched.run_until(1.0)
    by = {e.sender: e for e in trace}
    assert "collision" in by["a"].flags and "collision" in by["b"].flags
    assert by["c"].start == pytest.approx(by["a"].end + 500e-6) and "collision" not in by["c"].flags
    assert bus.stats.collisions == 2


def test_two_senders_starting_together_collide_and_see_it_in_their_echo():
    sched, bus, port, got, echoes, _ = make()
    a, b, c = port("a"), port("b"), port("c")
    a.send(b"\xf0\x0f")
    b.send(b"\x3c\xff")
    sched.run_until(1.0)
    assert bus.stats.collisions == 2
    heard = {d for _, d in got["c"]}
    assert heard == {bytes([0xF0 & 0x3C, 0x0F & 0xFF])}                # wired-AND of both
    assert echoes["a"][0][1] != echoes["a"][0][2] and echoes["b"][0][1] != echoes["b"][0][2]


def test_loss_corruption_delay():
    sched, bus, port, got, echoes, trace = make()
    a, b = port("a"), port("b")
    bus.fault = Fault(loss=1.0)
    a.send(b"\x01\x02")
    sched.run_until(0.1)
    assert got["b"] == [] and echoes["a"][0][2] == b"\x01\x02" and bus.stats.lost == 1
    bus.fault = Fault(corrupt=1.0)
    a.send(b"\x01\x02")
    sched.run_until(0.2)
    (t, d), = got["b"]
    diff = [x ^ y for x, y in zip(d, b"\x01\x02")]
    assert sum(bin(v).count("1") for v in diff) == 1 and echoes["a"][1][2] == d
    bus.fault = Fault(delay=0.05)
    a.send(b"\x07")
    sched.run_until(0.3)
    end = trace[-1].end
    assert got["b"][-1] == (pytest.approx(end + 0.05), b"\x07")


def test_muted_and_killed_stations():
    sched, bus, port, got, echoes, trace = make()
    a, b = port("a"), port("b")
    a.muted = True
    a.send(b"\x01")
    sched.run_until(0.1)
    assert got["b"] == [] and trace == []
    b.killed = True
    a.muted = False
    a.send(b"\x02")
    sched.run_until(0.2)
    assert got["b"] == [] and len(trace) == 1
