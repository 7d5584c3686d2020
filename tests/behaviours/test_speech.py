"""SSC speech (seed 3.2.6): resident messages, Repeat semantics, the run log, WAV through espeak-ng."""
from __future__ import annotations

import wave

import pytest

from arachnae_proto import messages as M
from arachnae_proto.enums import BusyStatus
from behaviours.speech import Speaker, Voice, espeak_available, resident_text, write_wav


class FakeClock:
    def __init__(self) -> None:
        self.t = 0.0

    def __call__(self) -> float:
        return self.t


SEED_TABLE = {  # seed 3.2.6, "SSC-residente Messages", copied from the document
    1: "Malfunction", 2: "Performing initialization", 3: "User input required", 4: "Enter command",
    5: "Obstacle detected", 6: "Performing Environment Scan", 7: "Scanning finished", 8: "Leg blocked",
    9: "JAC out of order", 10: "LCP out of order",
}


def test_resident_index_gives_the_seed_text():
    for index, text in SEED_TABLE.items():
        assert resident_text(index) == text
    for bad in (0, 11, 255):
        with pytest.raises(ValueError):
            resident_text(bad)


def test_speak_resident_message_from_the_wire():
    clock = FakeClock()
    ssc = Speaker(clock)
    msg = M.SpeakResident.decode(M.SpeakResident(repeat=1, index=5).encode())
    ssc.handle(msg)
    assert ssc.busy == BusyStatus.BUSY
    assert ssc.log[0].text == "Obstacle detected" and ssc.log[0].resident == 5


def test_repeat_n_says_the_text_n_times_back_to_back():
    clock = FakeClock()
    ssc = Speaker(clock)
    ssc.handle(M.Speak(repeat=3, text="Hello"))
    d = ssc.duration("Hello")
    clock.t = 100.0
    said = ssc.said()
    assert [text for _t, text in said] == ["Hello"] * 3
    assert [t for t, _ in said] == pytest.approx([0.0, d, 2 * d])
    assert [u.repetition for u in ssc.log] == [1, 2, 3]
    assert ssc.busy == BusyStatus.NOT_BUSY


def test_repeat_zero_repeats_until_a_new_string_arrives():
    clock = FakeClock()
    ssc = Speaker(clock)
    ssc.speak("Alarm", repeat=0)
    d = ssc.duration("Alarm")
    clock.t = 10 * d + d / 2                        # in the middle of the 11th saying
    assert len(ssc.said()) == 11 and ssc.busy == BusyStatus.BUSY
    ssc.speak_resident(4, repeat=1)                 # a new string: "Enter command"
    clock.t = 1000.0
    texts = [text for _t, text in ssc.said()]
    assert texts == ["Alarm"] * 11 + ["Enter command"]
    assert ssc.log[-1].start == pytest.approx(11 * d)   # waited for the saying in progress to end
    assert ssc.busy == BusyStatus.NOT_BUSY


def test_a_newer_waiting_string_replaces_an_older_one_and_repeat_is_checked():
    clock = FakeClock()
    ssc = Speaker(clock)
    ssc.speak("first", repeat=1)
    ssc.speak("second", repeat=1)
    ssc.speak("third", repeat=2)
    clock.t = 100.0
    assert [text for _t, text in ssc.said()] == ["first", "third", "third"]
    with pytest.raises(ValueError):
        ssc.speak("x", repeat=256)


def test_setup_changes_the_speaking_rate():
    clock = FakeClock()
    ssc = Speaker(clock)
    slow = ssc.duration("Scanning finished")
    ssc.handle(M.Setup(rate=15, amplitude=10, inflection=128, articulation=4, reserved=0))
    assert ssc.voice == Voice(15, 10, 128, 4)
    assert ssc.duration("Scanning finished") < slow


def test_wav_is_written_with_espeak_ng(tmp_path):
    # CI installs the Debian package espeak-ng: its absence is a failure, not a skip
    assert espeak_available(), "espeak-ng missing: apt-get install espeak-ng"
    out = write_wav(resident_text(1), tmp_path / "malfunction.wav")
    with wave.open(str(out)) as w:
        seconds = w.getnframes() / w.getframerate()
    assert 0.3 < seconds < 5.0                       # "Malfunction" is about a second of speech
    clock = FakeClock()
    ssc = Speaker(clock, wav_dir=tmp_path / "run")
    ssc.speak_resident(8, repeat=2)                  # "Leg blocked", twice: one file per string
    clock.t = 100.0
    ssc.advance()
    files = sorted((tmp_path / "run").glob("*.wav"))
    assert len(files) == 1 and ssc.log[0].wav == files[0] == ssc.log[1].wav
    assert files[0].stat().st_size > 1000
