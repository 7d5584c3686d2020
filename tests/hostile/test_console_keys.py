"""Issue 10, item 8: the RCP console reads VT100 escape sequences whole; no stray byte moves the robot."""
from __future__ import annotations

import pytest

from behaviours.rcp_keys import KeyDecoder, message_for_key
from behaviours.rcp_screen import Screen

# (name, bytes typed (one read per item), the keys that come out)
CASES = [
    ("up arrow", [b"\x1b[A"], ["F"]),
    ("down arrow", [b"\x1b[B"], ["B"]),
    ("right arrow", [b"\x1b[C"], ["R"]),
    ("left arrow", [b"\x1b[D"], ["L"]),
    ("arrow in application mode", [b"\x1bOB"], ["B"]),
    ("ctrl-up", [b"\x1b[1;5A"], ["F"]),
    ("F1 (SS3 P)", [b"\x1bOP"], []),
    ("F1 (CSI 11~)", [b"\x1b[11~"], []),
    ("F5", [b"\x1b[15~"], []),
    ("Home, End", [b"\x1b[H\x1b[F"], []),
    ("insert/delete", [b"\x1b[2~\x1b[3~"], []),
    ("alt-F", [b"\x1bF"], []),
    ("stray ESC then F", [b"\x1b", b"F"], []),
    ("ESC ESC then arrow", [b"\x1b\x1b[D"], ["L"]),
    ("sequence split over reads", [b"\x1b[", b"1;", b"2B"], ["B"]),
    ("cursor position report", [b"\x1b[12;40R"], []),
    ("bracketed paste markers", [b"\x1b[200~h\x1b[201~"], ["h"]),
    ("overlong parameters", [b"\x1b[" + b"1;" * 40 + b"B"], ["B"]),
    ("UTF-8 text", ["é".encode(), "ß€".encode()], []),
    ("8-bit CSI", [b"\x9bB"], ["B"]),
    ("control byte aborts a sequence", [b"\x1b[1\nB"], ["B"]),
    ("plain keys", [b"FbH 1"], ["F", "b", "H", " ", "1"]),
]


@pytest.mark.parametrize("name, reads, keys", CASES, ids=[c[0] for c in CASES])
def test_escape_sequences_are_read_whole(name, reads, keys):
    decoder = KeyDecoder()
    assert [k for data in reads for k in decoder.feed(data)] == keys


def test_no_byte_of_a_non_arrow_sequence_sends_a_command():
    """Every CSI/SS3 final byte with any parameters: only the four arrows give a key."""
    for final in range(0x40, 0x7F):
        for seq in (b"\x1b[" + bytes([final]), b"\x1b[3;5" + bytes([final]), b"\x1bO" + bytes([final])):
            keys = KeyDecoder().feed(seq)
            assert keys == ([{"A": "F", "B": "B", "C": "R", "D": "L"}[chr(final)]] if chr(final) in "ABCD" else []), seq
            assert all(message_for_key(k) is not None for k in keys)


@pytest.mark.parametrize("text", ["é", "\x00", "\x1b[2J", "日本", "\udcff"])
def test_the_screen_draws_any_text_as_ascii(text):
    out = Screen().status_line(f"? key {text!r}: no command") + Screen().lcd_line(0, text)
    out.decode("ascii")
    assert b"\x1b[2J" not in out


def test_non_ascii_on_the_rcp_line_does_not_crash_the_node(tmp_path):
    """A run whose operator line carries UTF-8 and escape sequences: one MOVE (the down arrow), no crash."""
    from sim2d.scenario import load_scenario
    from sim2d.runner import load_spec_once
    from sim2d.sim import Simulation

    path = tmp_path / "s.yaml"
    path.write_text("duration: 3\narena: {size: [3, 3]}\nrobot: {pose: [1.5, 1.5, 0], task: idle}\n")
    spec = load_spec_once()
    sim = Simulation(load_scenario(path, spec), spec)
    sim.sched.at(1.0, lambda: sim.rcp.type(sim.sched.now, "é\x1bOP\x1b[B\x1b".encode()))
    result = sim.run()
    uic = result.metrics["nodes"]["UIC/RCP"]
    assert uic["keys"] == 1 and uic["commands"] == {"MOVE BACKWARD": 1}
