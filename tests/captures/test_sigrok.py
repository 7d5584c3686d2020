"""The generated sigrok decoder on UART waveforms synthesised from a simulation's capture (issue 13).

`arachnae capture vcd` turns the run's bus.pcapng into the logic levels of each
bus at its baud rate; sigrok-cli decodes them with its own uart decoder and the
generated `arachnae` decoder stacked on it. Every frame of the trace must come
out: same start time (within a bit), same bytes, the same message as the codec
decoded (or the same kind of error), and every field annotated as the codec
shows it.
"""
from __future__ import annotations

import doctest
import json
import subprocess
from pathlib import Path
from typing import NamedTuple

import pytest

from arachnae.cli import main
from arachnae_proto import CodecError, frame
from arachnae_proto.network import name_of
from captures.pcapng import CapturedFrame
from captures.vcd import capture_vcd, low_intervals

ROOT = Path(__file__).resolve().parents[2]
BUSES = ("first", "sensor", "joints3")      # 9600 and 2400 baud with corrupt frames; 19200 with collisions


class Event(NamedTuple):
    start_us: float
    end_us: float
    row: str          # annotation row: Frames, Messages, Fields, Errors
    text: str


@pytest.fixture(scope="module")
def vcd(bus_run, tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("vcd") / "buses.vcd"
    assert main(["capture", "vcd", str(bus_run), *[a for b in BUSES for a in ("--bus", b)], "--out", str(out)]) == 0
    return out


def sigrok(vcd: Path, bus, env: dict) -> list[Event]:
    env = dict(env, SIGROKDECODE_DIR=str(ROOT / "generated" / "sigrok"))
    p = subprocess.run(["sigrok-cli", "-I", "vcd", "-i", str(vcd),
                        "-P", f"uart:baudrate={bus.baud}:rx={bus.name},arachnae:bus={bus.name}",
                        "-A", "arachnae", "--protocol-decoder-jsontrace"],
                       capture_output=True, text=True, env=env, timeout=300)
    assert p.returncode == 0 and "Traceback" not in p.stderr, p.stderr
    events, open_ = [], {}
    for e in json.loads(p.stdout)["traceEvents"]:
        key = (e["tid"], e["name"])
        if e["ph"] == "B":
            open_.setdefault(key, []).append(e["ts"])
        else:
            events.append(Event(open_[key].pop(0), e["ts"], e["tid"], e["name"]))
    return sorted(events, key=lambda e: (e.start_us, e.row))


def line_bursts(rows):
    """Trace rows as the line carried them: frames that overlap in time (a collision) are one burst."""
    bursts = []
    for r in sorted(rows, key=lambda r: r.start_s):
        if bursts and r.start_s < bursts[-1][-1].end_s:
            bursts[-1].append(r)
        else:
            bursts.append([r])
    for b in bursts:
        assert len(b) == 1 or all("collision" in r.flags for r in b), b
    return [max(b, key=lambda r: len(r.data)) for b in bursts]


def field_texts(data: bytes) -> set[str]:
    """What the decoder must annotate for a good frame: header, CRC and every field as the codec shows it."""
    f = frame.parse(data)
    m = f.message
    out = {f"dst={name_of(f.dst)}", f"src={name_of(f.src)}", f"opcode={m.NAME}", f"length={len(data) - frame.OVERHEAD}",
           f"crc=0x{data[-2:].hex().upper()}"}
    out |= {f"{info.name}={info.describe(getattr(m, info.name))}" for info in m.FIELDS
            if not (info.name == m.ARRAY and len(getattr(m, info.name)) == 0)}
    return out


@pytest.mark.parametrize("bus_name", BUSES)
def test_decoded_frames_equal_the_trace(vcd, trace, spec, tool_env, bus_name):
    bus = spec.buses[bus_name]
    events = sigrok(vcd, bus, tool_env)
    frames = [e for e in events if e.row == "Frames"]
    messages = [e for e in events if e.row == "Messages"]
    expected = line_bursts([r for r in trace if r.bus == bus_name])
    assert len(expected) > 20
    assert [bytes.fromhex(e.text) for e in frames] == [r.data for r in expected]
    assert len(messages) == len(frames)
    bit_us = 1e6 / bus.baud
    bad = 0
    for fr, msg, row in zip(frames, messages, expected):
        assert abs(fr.start_us - row.start_s * 1e6) <= bit_us, (fr, row)        # the start bit, to a bit
        assert (msg.start_us, msg.end_us) == (fr.start_us, fr.end_us)
        try:
            frame.parse(row.data)
        except CodecError as err:
            bad += 1
            assert msg.text.endswith(f"<{err.kind.name}>") and row.message.startswith(f"<{err.kind.name}:"), (msg, row)
            errors = [e for e in events if e.row == "Errors" and e.start_us == fr.start_us]
            assert any(e.text.startswith(f"{err.kind.name}: ") for e in errors), (errors, row)
            continue
        assert msg.text == f"{row.src} -> {row.dst} {row.message}", (msg, row)
        fields = {e.text for e in events if e.row == "Fields" and fr.start_us <= e.start_us and e.end_us <= fr.end_us}
        assert fields == field_texts(row.data), (row, fields)
    if bus_name != "joints3":
        assert bad > 0                          # the injected corruption is decoded as such


def test_every_vector_frame_gets_the_codecs_verdict(vectors, spec, tool_env, tmp_path):
    """Every frame of the shared vectors, good and bad, on one line: the decoder's verdict is the codec's without
    an own address (a decoder on the line is no node), ROUTE included (issue 10), and a good frame reads as the codec
    describes it."""
    bus = max(spec.buses.values(), key=lambda b: b.baud)
    char_ns = bus.bits_per_char * 10**9 // bus.baud
    datas = [bytes.fromhex(v[3]) for v in vectors if v[0] in ("msg", "bad") and v[3] != "-"]
    frames, t = [], 10 * char_ns                                    # the line idles first, so the UART syncs
    for d in datas:
        frames.append(CapturedFrame(bus.name, t, d))
        t += (len(d) + int(bus.idle_gap_chars) + 2) * char_ns        # then the line idles past the gap
    vcd = capture_vcd(tmp_path / "vectors.vcd", frames, {bus.name: bus})
    # the Messages row as text: sigrok-cli's JSON trace leaves quotes in annotations unescaped (SPEAK's text)
    p = subprocess.run(["sigrok-cli", "-I", "vcd", "-i", str(vcd), "-P", f"uart:baudrate={bus.baud}:rx={bus.name},arachnae:bus={bus.name}",
                        "-A", "arachnae=messages"], capture_output=True, text=True, timeout=300,
                       env=dict(tool_env, SIGROKDECODE_DIR=str(ROOT / "generated" / "sigrok")))
    assert p.returncode == 0 and "Traceback" not in p.stderr, p.stderr
    messages = [line.split(": ", 1)[1] for line in p.stdout.splitlines()]
    assert len(messages) == len(datas)
    verdicts = []
    for d, msg in zip(datas, messages):
        try:
            f = frame.parse(d)
        except CodecError as err:
            verdicts.append(err.kind.name)
            assert msg.endswith(f"<{err.kind.name}>"), (d.hex(), msg)
            continue
        verdicts.append("OK")
        assert msg == f"{name_of(f.src)} -> {name_of(f.dst)} {f.message.describe()}", (d.hex(), msg)
    route = [v for v in vectors if v[0] == "bad" and v[4] == "ROUTE" and v[2] == "-"]
    assert route and all(verdicts[datas.index(bytes.fromhex(v[3]))] == "ROUTE" for v in route)
    assert {"OK", "TRUNCATED", "OVERSIZE", "CHECKSUM", "ROUTE", "OPCODE", "LENGTH", "RANGE"} <= set(verdicts)


def test_waveform_is_8n1_lsb_first_and_wired_and():
    # 0x35 = 0b00110101 at 1 bit per time unit: start 0, then bits 1 0 1 0 1 1 0 0, stop 1
    lows = low_intervals([CapturedFrame("b", 0, b"\x35")], baud=10**9, bits_per_char=10, unit_ns=1)
    assert lows == [(0, 1), (2, 3), (4, 5), (7, 9)]
    # two senders at once: the line is low where either is low (wired-AND), 0x35 & 0x0F = 0x05
    both = low_intervals([CapturedFrame("b", 0, b"\x35"), CapturedFrame("b", 0, b"\x0f")], 10**9, 10, 1)
    assert both == low_intervals([CapturedFrame("b", 0, b"\x05")], 10**9, 10, 1)
    # the next byte starts after the stop bits; 11 bits per char means two stop bits
    two = low_intervals([CapturedFrame("b", 5, b"\xff\xff")], 10**9, 11, 1)
    assert two == [(5, 6), (16, 17)]


def test_vcd_doctests():
    import captures.vcd

    assert doctest.testmod(captures.vcd).failed == 0


def test_cli_errors_are_one_line(bus_run, tmp_path, capsys):
    assert main(["capture", "vcd", str(tmp_path / "none")]) == 1
    assert main(["capture", "vcd", str(bus_run), "--bus", "nobus"]) == 1
    assert main(["capture", "vcd", str(bus_run), "--out", str(tmp_path / "no" / "dir.vcd")]) == 1
    (tmp_path / "junk.pcapng").write_bytes(b"junk")
    assert main(["capture", "vcd", str(tmp_path / "junk.pcapng")]) == 1
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 4 and "no such capture" in err[0] and "not a bus of the spec" in err[1]
    assert "no such folder" in err[2] and "pcapng capture" in err[3]
    assert not list(tmp_path.glob("*.vcd")) and not list(tmp_path.glob(".*"))


def test_vcd_never_replaces_a_users_file(bus_run, vcd, tmp_path, capsys):
    """issue 10.1: --out naming the user's own file is refused; a VCD this command wrote is replaced."""
    mine = tmp_path / "mine.vcd"
    mine.write_text("my own waveforms\n")
    assert main(["capture", "vcd", str(bus_run), "--bus", "sensor", "--out", str(mine)]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "was not written by `arachnae capture vcd`" in err
    assert mine.read_text() == "my own waveforms\n"
    again = tmp_path / "again.vcd"
    again.write_bytes(vcd.read_bytes())
    assert main(["capture", "vcd", str(bus_run), "--bus", "sensor", "--out", str(again)]) == 0
    assert again.read_bytes() != vcd.read_bytes()            # replaced by the sensor bus alone


def test_spec_strings_stay_python_strings(hostile_spec, monkeypatch):
    """The decoder is Python for sigrok's interpreter: spec text goes in as repr() literals, shown exactly."""
    import sys
    import types

    from codegen.generate import render

    from .conftest import HOSTILE_UNIT

    files = {p.name: d for p, d in render(hostile_spec, ("sigrok",)).items()}
    fake = types.ModuleType("sigrokdecode")
    fake.Decoder, fake.OUTPUT_ANN = object, 0
    monkeypatch.setitem(sys.modules, "sigrokdecode", fake)       # what sigrok's interpreter provides
    pd = types.ModuleType("pd_hostile")
    exec(compile(files["pd.py"], "pd.py", "exec"), pd.__dict__)
    m = pd.MESSAGES[hostile_spec.message("XMIT_DATA_PSC").opcode]
    assert pd.describe(m.fields[0], 160) == f"4.8 {HOSTILE_UNIT} (raw 160)"
