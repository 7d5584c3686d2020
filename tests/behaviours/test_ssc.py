"""SSC node (seed 3.2.6): SPEAK and resident messages reach its speech output; STATUS_ACK says BUSY while it speaks."""
from __future__ import annotations

from arachnae_proto import messages as M
from arachnae_proto.enums import BusyStatus, SscMessage
from arachnae_proto.network import ADDRESS_OF

from tests.behaviours.rig import Rig

MCP, SSC = ADDRESS_OF["MCP"], ADDRESS_OF["SSC"]


def test_speak_frames_are_said_and_status_is_busy_meanwhile(spec):
    rig = Rig(spec, "SSC", SSC)
    rig.inject(0.1, MCP, M.SpeakResident(repeat=1, index=int(SscMessage.OBSTACLE_DETECTED)))
    rig.inject(0.2, MCP, M.StatusReq())
    rig.run(0.3)
    said = rig.node.speaker.said()
    assert [text for _t, text in said] == ["Obstacle detected"]      # seed 3.2.6 resident message 5
    acks = rig.frames(M.StatusAckBusy, MCP)
    assert acks and acks[-1][1].message.status == BusyStatus.BUSY
    rig.inject(5.0, MCP, M.StatusReq())
    rig.run(5.1)
    assert rig.frames(M.StatusAckBusy, MCP)[-1][1].message.status == BusyStatus.NOT_BUSY


def test_free_text_is_spoken_as_sent(spec):
    rig = Rig(spec, "SSC", SSC)
    rig.inject(0.1, MCP, M.Speak(repeat=2, text=b"HELLO"))
    rig.run(10.0)
    assert [text for _t, text in rig.node.speaker.said()] == ["HELLO", "HELLO"]   # Repeat 2


def test_run_log_and_wav_files_in_the_output_folder(spec, tmp_path):
    """speech.tsv lists every utterance; write_wavs synthesizes each text once (espeak-ng, scripts/apt-packages.txt)."""
    import csv

    rig = Rig(spec, "SSC", SSC)
    rig.inject(0.1, MCP, M.SpeakResident(repeat=2, index=int(SscMessage.LEG_BLOCKED)))
    rig.inject(0.2, MCP, M.Speak(repeat=1, text=b"STOP"))
    rig.run(10.0)
    rig.node.write_artifacts(tmp_path)
    rows = list(csv.DictReader(open(tmp_path / "speech.tsv"), delimiter="\t"))
    assert [(r["text"], r["repetition"], r["resident"]) for r in rows] == \
        [("Leg blocked", "1", "8"), ("STOP", "1", "")]     # the new string waits for the utterance to end
    assert float(rows[0]["start_s"]) >= 0.1 and float(rows[1]["start_s"]) == float(rows[0]["end_s"])
    assert rig.node.debug_metrics() == {"utterances": 2, "texts": ["Leg blocked", "STOP"]}
    wavs = rig.node.write_wavs(tmp_path / "speech")
    assert [w.name for w in wavs] == ["001.wav", "002.wav"]
    assert all(w.read_bytes()[:4] == b"RIFF" and w.stat().st_size > 1000 for w in wavs)
