"""The optional first-level nodes (seed 3.2.6-3.2.9): SSC, APU/SDF, UIC/RCP, RLC.

In the simulation they take part in POST and answer status requests (the
skeleton's common handling). The SSC speaks through behaviours.speech (its
run log; a WAV per utterance when the host gives it a folder); sound direction,
the user interface and the radio link have no simulated hardware yet.
"""
from __future__ import annotations

from arachnae_proto import messages as M
from arachnae_proto.skeletons.apu_sdf import ApuSdfSkeleton
from arachnae_proto.skeletons.rlc import RlcSkeleton
from arachnae_proto.skeletons.ssc import SscSkeleton
from arachnae_proto.skeletons.uic_rcp import UicRcpSkeleton

from behaviours.runtime import Runtime
from behaviours.speech import Speaker


class SSC(Runtime, SscSkeleton):
    """seed 3.2.6: speech output of SPEAK strings and the resident messages."""

    def __init__(self, *args, **kwargs) -> None:
        super().__init__(*args, **kwargs)
        self.speaker = Speaker(self.hw.now, wav_dir=getattr(self.cfg, "speech_wav_dir", None))

    def on_setup(self, src: int, msg: M.Setup) -> None:
        self.speaker.handle(msg)

    def on_speak(self, src: int, msg: M.Speak) -> None:
        self.speaker.handle(msg)

    def on_speak_resident(self, src: int, msg: M.SpeakResident) -> None:
        self.speaker.handle(msg)

    def status_ack(self) -> M.Message:
        """seed 3.2.6: BUSY while speaking."""
        return M.StatusAckBusy(status=int(self.speaker.busy))


class APU_SDF(Runtime, ApuSdfSkeleton):
    pass


class UIC_RCP(Runtime, UicRcpSkeleton):
    pass


class RLC(Runtime, RlcSkeleton):
    pass
