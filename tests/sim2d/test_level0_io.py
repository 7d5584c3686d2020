"""Scenario `operator:` keys, `speech:` and `sounds:` as the level-0 boards see them (sim2d.level0_io)."""
from __future__ import annotations

import math

import pytest

from arachnae.errors import UserError
from sim2d.level0_io import Microphones, RcpLine, SDF_NOISE_DEG
from sim2d.scenario import load_scenario

BASE = """\
duration: 10
arena: {size: [4, 3]}
robot: {pose: [1, 1, 90]}
"""


def test_operator_keys_and_speech_option_load_sorted(write):
    sc = load_scenario(write("s.yaml", BASE + 'operator:\n  - {at: 4, keys: "H"}\n  - {at: 2.5, keys: "f 1"}\n'
                                              "speech: {wav: true}\n"))
    assert [(o.at, o.keys) for o in sc.operator] == [(2.5, "f 1"), (4.0, "H")]
    assert sc.speech_wav
    plain = load_scenario(write("p.yaml", BASE))
    assert plain.operator == () and not plain.speech_wav


def test_operator_keys_concatenate_across_includes(write):
    write("inc.yaml", 'operator: [{at: 1, keys: "F"}]\n')
    sc = load_scenario(write("s.yaml", "include: inc.yaml\n" + BASE + 'operator: [{at: 2, keys: "H"}]\n'))
    assert [o.keys for o in sc.operator] == ["F", "H"]


@pytest.mark.parametrize("extra, line, fragment", [
    ('operator:\n  - {at: 1, keys: "FZ"}\n', 5, "'Z' is not an RCP key"),
    ('operator:\n  - {at: -1, keys: "F"}\n', 5, "at: must be >= 0"),
    ("operator:\n  - {at: 1}\n", 5, "missing required key 'keys'"),
    ('operator:\n  - {at: 1, keys: ""}\n', 5, "give at least one key"),
    ('operator: {at: 1, keys: "F"}\n', 4, "operator: expected a list"),
    ("speech: {wav: maybe}\n", 4, "speech.wav: expected true or false"),
    ("speech: {mp3: true}\n", 4, "unknown key 'mp3'"),
])
def test_bad_operator_or_speech_is_one_line_with_file_and_line(write, extra, line, fragment):
    p = write("bad.yaml", BASE + extra)
    with pytest.raises(UserError) as exc:
        load_scenario(p)
    msg = str(exc.value)
    assert msg.startswith(f"{p}:{line}: ") and fragment in msg and "\n" not in msg, msg


def test_rcp_line_buffers_keys_until_read_and_keeps_the_screen():
    line = RcpLine()
    line.type(1.0, b"F")
    line.type(1.5, b"H")
    assert line.read() == b"FH" and line.read() == b""
    line.write(b"\x1b[2J")
    assert bytes(line.screen) == b"\x1b[2J" and [t for t, _k in line.typed] == [1.0, 1.5]


@pytest.mark.parametrize("pose, source, direction", [
    ((0.0, 0.0, 0.0), (0.0, 2.0), 90.0),                     # to the left: counter-clockwise from forward
    ((0.0, 0.0, 0.0), (0.0, -2.0), 270.0),                   # to the right
    ((1.0, 1.0, math.pi / 2), (1.0, 3.0), 0.0),              # straight ahead of a robot facing +y
    ((1.0, 1.0, math.pi / 2), (3.0, 1.0), 270.0),
])
def test_microphones_give_the_direction_in_the_body_frame(pose, source, direction):
    mic = Microphones(seed=1)
    mic.hear(0.0, pose, source, 80.0)
    rel, level = mic.next()
    err = (rel - direction + 180.0) % 360.0 - 180.0
    assert abs(err) < 4 * SDF_NOISE_DEG
    assert level == pytest.approx(80.0 - 20 * math.log10(2.0))         # 6 dB per doubling beyond 1 m
    assert mic.next() is None


def test_interactive_console_scenario_loads(spec):
    from pathlib import Path

    sc = load_scenario(Path(__file__).resolve().parents[2] / "scenarios" / "interactive" / "console.yaml", spec)
    assert sc.task == "idle" and sc.operator == ()
