"""`arachnae monitor` and `arachnae replay` wired together through a pty pair (issue 13, deliverable 4).

socat links two ptys; replay writes one bus of the simulation's capture onto one
end with its original timing, the monitor (a separate process, as a user runs
it) reads the other end, prints one line per frame and records a pcapng. A pty
is not a UART: nothing here asserts wall times, only bytes, decoding and order.
"""
from __future__ import annotations

import json
import signal
import subprocess
import sys
import time
from collections import Counter
from pathlib import Path

import pytest
from arachnae_proto.network import BUSES

from arachnae.cli import main
from captures.decode import decode
from captures.monitor import FrameSplitter, LiveTable, MonitorStats, RawFrame
from captures.pcapng import CapturedFrame, read_file
from captures.replay import schedule

BUS = "first"        # the MCP's bus in the shared run: corrupt frames and collisions among the good ones
GOOD = bytes.fromhex("042707010048c8")            # STATUS_ACK_RANGE, from the shared vectors


def _cli_stdout(capsys, argv: list[str], want_rc: int) -> str:
    capsys.readouterr()
    rc = main(argv)
    out = capsys.readouterr().out
    assert rc == want_rc, out
    return out


def wait_for(predicate, timeout: float, what: str) -> None:
    end = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() > end:
            raise AssertionError(f"timed out waiting for {what}")
        time.sleep(0.05)


@pytest.fixture
def pty_pair(tmp_path):
    """Two linked ptys (socat): what one end is written, the other end reads."""
    a, b = tmp_path / "ttyA", tmp_path / "ttyB"
    proc = subprocess.Popen(["socat", f"pty,raw,echo=0,link={a}", f"pty,raw,echo=0,link={b}"],
                            stderr=subprocess.DEVNULL)
    try:
        wait_for(lambda: a.exists() and b.exists(), 10, "socat's ptys")
        yield a, b
    finally:
        proc.terminate()
        proc.wait(timeout=10)


def test_replay_onto_a_pty_arrives_decoded_byte_identical_and_in_order(bus_run, trace, pty_pair, tmp_path, capsys):
    a, b = pty_pair
    sent = [f for f in read_file(bus_run / "bus.pcapng").frames if f.bus == BUS]
    assert len(sent) > 20
    out, err, rec = tmp_path / "monitor.tsv", tmp_path / "monitor.err", tmp_path / "monitor.pcapng"
    with open(out, "w") as fo, open(err, "w") as fe:
        mon = subprocess.Popen([sys.executable, "-m", "arachnae", "monitor", str(b), "--bus", BUS, "--pcapng", str(rec)],
                               stdout=fo, stderr=fe)            # stdout is no terminal: plain lines
        try:
            wait_for(lambda: "monitoring" in err.read_text(), 30, "the monitor to open its port")
            assert main(["replay", str(bus_run), str(a), "--bus", BUS, "--speed", "1"]) == 0
            wait_for(lambda: len(out.read_text().splitlines()) >= len(sent), 30, "every frame at the monitor")
            time.sleep(0.2)                                      # nothing more may come
        finally:
            mon.send_signal(signal.SIGINT)                       # Ctrl-C: a clean end with a summary
            rc = mon.wait(timeout=30)
    assert rc == 0, err.read_text()

    # every frame, in order, byte-identical, decoded as the codec (and the simulator's trace) decodes it
    lines = [line.split("\t") for line in out.read_text().splitlines()]
    want = [r for r in trace if r.bus == BUS]
    assert [row[5] for row in lines] == [f.data.hex() for f in sent] == [r.data.hex() for r in want]
    for row, f, r in zip(lines, sent, want):
        d = decode(f.data)
        assert row[1:5] == [BUS, d.src, d.dst, d.text] == [BUS, r.src, r.dst, r.message]
    times = [float(row[0]) for row in lines]
    assert times == sorted(times)

    # the summary counts the codec's error kinds; the run's corrupt frames and collisions show as errors
    errors = Counter(decode(f.data).name for f in sent if decode(f.data).message is None)
    assert errors and sum(errors.values()) < len(sent)
    summary = err.read_text()
    assert f"{len(sent)} frames" in summary and "Traceback" not in summary
    for kind, n in errors.items():
        assert f"error {kind}: {n}" in summary

    # the monitor's own capture: one interface for the bus, every frame's bytes in order
    cap = read_file(rec)
    assert [(i.name, i.speed_bps) for i in cap.interfaces] == [(BUS, BUSES[BUS].baud)]
    assert [f.data for f in cap.frames] == [f.data for f in sent]
    assert [f.time_ns for f in cap.frames] == sorted(f.time_ns for f in cap.frames)
    # issue 11: the trace validator reads the monitor's capture as it reads a run's trace. A pty's time stamps
    # are not the line's, so only the rules that need no clock apply (--untimed): ID retries by order,
    # relays, MOVE retries; every frame is read, and the MCP's identifications are checked
    report = json.loads(_cli_stdout(capsys, ["trace", "check", str(rec), "--untimed", "--json"], want_rc=0))
    assert report["violations"] == 0, report["all"]
    assert report["checked"]["id_req"] >= sum(1 for f in sent if decode(f.data).name == "ID_REQ") > 0


def test_splitter_cuts_by_length_byte_and_idle_gap(spec):
    sp = FrameSplitter(spec)
    two = GOOD + GOOD
    assert sp.feed(two[:3], 1) == []
    assert sp.feed(two[3:], 2) == [RawFrame(1, GOOD), RawFrame(2, GOOD)]   # back to back: the length byte splits
    assert sp.gap() is None
    bad_length = GOOD[:3] + bytes([GOOD[3] + 5]) + GOOD[4:]               # says 5 bytes more than it has
    assert sp.feed(bad_length, 3) == []
    assert sp.gap() == RawFrame(3, bad_length)                             # the idle gap ends it
    assert decode(bad_length).name == "TRUNCATED"
    assert sp.feed(GOOD, 4) == [RawFrame(4, GOOD)]                         # and the next frame is in step again


def test_live_table_shows_rates_last_values_and_errors():
    from rich.console import Console

    stats = MonitorStats(started=0.0)
    for i in range(4):
        stats.add(decode(GOOD), GOOD, now=1.0 + i)
    corrupt = GOOD[:-1] + bytes([GOOD[-1] ^ 1])
    stats.add(decode(corrupt), corrupt, now=4.5)
    assert stats.rate("STATUS_ACK_RANGE", now=5.0) == pytest.approx(4 / 5)
    assert stats.rate("STATUS_ACK_RANGE", now=8.5) == pytest.approx(1 / 5)   # 3 of 4 left the 5 s window
    console = Console(record=True, width=160)
    console.print(LiveTable(stats, "test"))
    text = console.export_text()
    row = next(line for line in text.splitlines() if "STATUS_ACK_RANGE" in line)
    assert "4" in row and decode(GOOD).message.describe().split(" ", 1)[1] in row
    assert "CHECKSUM" in text and "5 frames, 35 bytes" in text


def test_schedule_scales_time_and_keeps_a_frame_gap(spec):
    bus = spec.buses[BUS]
    frames = [CapturedFrame(BUS, 10_000_000_000, GOOD), CapturedFrame(BUS, 10_100_000_000, GOOD),
              CapturedFrame(BUS, 10_100_000_001, GOOD)]                    # the last starts 1 ns after the second
    at = schedule(frames, bus, speed=2.0)
    assert at[:2] == [0.0, 0.05]
    assert at[2] == pytest.approx(0.05 + (bus.frame_time_us(len(GOOD)) + bus.frame_gap_us) * 1e-6)


@pytest.mark.parametrize("argv, message", [
    (["monitor", "/nonexistent/tty"], "/nonexistent/tty: cannot open the port"),
    (["monitor", "/dev/null", "--bus", "nosuchbus"], "--bus nosuchbus: not a bus of the spec"),
    (["replay", "{run}", "/nonexistent/tty", "--bus", BUS], "/nonexistent/tty: cannot open the port"),
    (["replay", "{run}", "/dev/null", "--speed", "0", "--bus", BUS], "--speed: expected a factor > 0"),
    (["replay", "{run}", "/dev/null", "--speed", "-2"], "--speed: expected a factor > 0"),
    (["replay", "{run}", "/dev/null"], "holds the buses first, leg, sensor"),
    (["replay", "{bad}", "/dev/null"], "not a readable pcapng capture"),
    (["replay", "{missing}", "/dev/null"], "no such capture"),
])
def test_bad_input_is_one_line(bus_run, tmp_path, capsys, argv, message):
    bad = tmp_path / "bad.pcapng"
    bad.write_bytes(b"no capture here")
    argv = [a.format(run=bus_run, bad=bad, missing=tmp_path / "missing.pcapng") for a in argv]
    assert main(argv) == 1
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1 and "Traceback" not in err


def test_monitor_never_overwrites_a_file_and_leaves_none_when_the_port_fails(tmp_path, capsys):
    keep = tmp_path / "keep.pcapng"
    keep.write_bytes(b"precious")
    assert main(["monitor", "/nonexistent/tty", "--pcapng", str(keep)]) == 1
    assert "exists already" in capsys.readouterr().err and keep.read_bytes() == b"precious"
    fresh = tmp_path / "new.pcapng"
    assert main(["monitor", "/nonexistent/tty", "--pcapng", str(fresh)]) == 1
    assert "cannot open the port" in capsys.readouterr().err and not fresh.exists()


def test_monitor_stops_after_count_frames(capsys):
    """--count N ends the monitor by itself after N frames; the idle gap (not the length byte) ends a short one."""
    import os
    import termios
    import threading

    master, slave = os.openpty()
    try:
        def talk():
            # pyserial sets the line raw, then flushes its input, when it opens it: write after that
            wait_for(lambda: not termios.tcgetattr(slave)[3] & termios.ICANON, 60, "the monitor to open the pty")
            time.sleep(0.3)
            os.write(master, GOOD[:5])                 # a frame cut short: the idle gap ends it
            time.sleep(0.2)
            os.write(master, GOOD + GOOD)              # two frames back to back: the length byte splits them

        writer = threading.Thread(target=talk)
        writer.start()
        assert main(["monitor", os.ttyname(slave), "--bus", BUS, "--count", "2"]) == 0
        writer.join()
    finally:
        os.close(master)
        os.close(slave)
    out, err = capsys.readouterr()
    lines = [line.split("\t") for line in out.splitlines()]
    assert [(row[4].split(":")[0], row[5]) for row in lines] == [("<TRUNCATED", GOOD[:5].hex()),
                                                                 (decode(GOOD).text, GOOD.hex())]
    assert "2 frames" in err and "error TRUNCATED: 1" in err
