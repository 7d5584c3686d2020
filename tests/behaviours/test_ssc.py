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
