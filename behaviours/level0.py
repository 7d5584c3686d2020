"""The optional first-level nodes (seed 3.2.6-3.2.9): SSC, APU/SDF, UIC/RCP, RLC.

  SSC      speaks through behaviours.speech (its run log: speech.tsv in the
           run's output folder; WAV files when the host asks for them);
  APU/SDF  turns a sound event its microphones report into an XMIT_RECORD
           for the NP3 (direction in the body frame, level in dB);
  UIC/RCP  reads the operator's keys from its RS-232 line (a VT100 terminal,
           seed 4.1), sends them as MOVE / POST_REQ records, and draws the
           two-line LCD and the alerts on that terminal;
  RLC      takes part in POST only (no radio is simulated).

The key table and the VT100 picture are the pure modules behaviours.rcp_keys and
behaviours.rcp_screen; the decisions (which record, when) are taken here.
"""
from __future__ import annotations

import csv
from pathlib import Path
from typing import TypedDict

from arachnae_proto import messages as M
from arachnae_proto.enums import BusyStatus, MovCmd, RecordKind
from arachnae_proto.network import ADDRESS_OF
from arachnae_proto.skeletons.apu_sdf import ApuSdfSkeleton
from arachnae_proto.skeletons.rlc import RlcSkeleton
from arachnae_proto.skeletons.ssc import SscSkeleton
from arachnae_proto.skeletons.uic_rcp import UicRcpSkeleton

from behaviours import tuning as T
from behaviours.runtime import Runtime
from behaviours.speech import Speaker, write_wav
from behaviours.rcp_keys import KeyDecoder, label_for_key, message_for_key
from behaviours.rcp_screen import Screen
from behaviours.units import age_byte

_MCP, _NP3 = ADDRESS_OF["MCP"], ADDRESS_OF["NP3"]
_REDRAW = "\x0c"          # Ctrl-L: the terminal asks for the whole picture again


class SscDebug(TypedDict):
    """SSC.debug_metrics(): metrics.json `nodes.SSC` (sim2d.metrics checks expectations on it at load)."""
    utterances: int
    texts: list[str]


class SSC(Runtime, SscSkeleton):
    """seed 3.2.6: speech output of SPEAK strings and the resident messages."""

    def __init__(self, *args, **kwargs) -> None:
        super().__init__(*args, **kwargs)
        self.speaker = Speaker(self.hw.now, wav_dir=getattr(self.cfg, "speech_wav_dir", None))

    def on_setup(self, src: int, msg: M.Setup) -> None:
        self.speaker.handle(msg)

    def on_speak(self, src: int, msg: M.Speak) -> None:
        self.speaker.handle(msg)
        self.hw.note("speech", text=msg.text.decode("latin-1"))

    def on_speak_resident(self, src: int, msg: M.SpeakResident) -> None:
        self.speaker.handle(msg)
        self.hw.note("speech", index=int(msg.index))

    def status_ack(self) -> M.Message:
        """seed 3.2.6: BUSY while speaking."""
        return M.StatusAckBusy(status=int(self.speaker.busy))

    # -- debug port: the run log ------------------------------------------------------------
    def debug_metrics(self) -> SscDebug:
        said = self.speaker.said()
        return {"utterances": len(said), "texts": sorted({text for _t, text in said})}

    def write_artifacts(self, out_dir: Path) -> None:
        """speech.tsv: one line per utterance (start time, end time, repetition, resident index, text)."""
        self.speaker.advance()
        with open(Path(out_dir) / "speech.tsv", "w", newline="") as fh:
            w = csv.writer(fh, delimiter="\t", lineterminator="\n")
            w.writerow(["start_s", "end_s", "repetition", "resident", "text"])
            for u in self.speaker.log:
                w.writerow([f"{u.start:.3f}", f"{u.end:.3f}", u.repetition, u.resident or "", u.text])

    def write_wavs(self, wav_dir: Path) -> list[Path]:
        """Each utterance's first saying as a WAV via espeak-ng (the SSI263 stand-in): NNN.wav."""
        out = []
        for i, u in enumerate(self.speaker.log, 1):
            if u.repetition == 1:
                out.append(write_wav(u.text, Path(wav_dir) / f"{i:03d}.wav", self.speaker.voice))
        return out


class _Records:
    """seed 3.2.2 message scheduling for a first-level slave: XMIT_REQ, then the record on XMIT_GRANT."""

    def _records_init(self) -> None:
        self.outbox: list[M.Message] = []
        self.last_record: M.Message | None = None
        self.records_sent = 0

    def queue_record(self, msg: M.Message) -> None:
        self.outbox.append(msg)
        if len(self.outbox) == 1:
            self.slave_send(_MCP, M.XmitReq())  # type: ignore[attr-defined]

    def on_xmit_grant(self, src: int, msg: M.XmitGrant) -> None:
        """seed 3.2.2: the MCP fetches our record; a repeated grant means it did not get through."""
        if not self.outbox:
            if isinstance(self.last_record, (M.Move, M.XmitRecord)):   # a POST_REQ is never repeated
                self.send(src, self.last_record)  # type: ignore[attr-defined]
            return
        rec = self.outbox.pop(0)
        self.last_record = rec
        self.records_sent += 1
        self.send(src, rec)  # type: ignore[attr-defined]
        self.record_sent(rec)
        if self.outbox:
            self.slave_send(src, M.XmitReq())  # type: ignore[attr-defined]

    def record_sent(self, rec: M.Message) -> None:
        """Hook: a record left for the MCP."""


class ApuSdfDebug(TypedDict):
    """APU_SDF.debug_metrics(): metrics.json `nodes.APU/SDF`."""
    events_heard: int
    events_too_quiet: int
    records_sent: int


class APU_SDF(_Records, Runtime, ApuSdfSkeleton):
    """seed 3.2.7, 4.3: detect a sound event and the direction it came from; report it to the NP3."""

    def start(self) -> None:
        self._records_init()
        self.processing: tuple[float, float] | None = None   # the event whose direction is being found
        self.heard = 0
        self.ignored = 0
        self.every(T.APU_POLL_S, self.listen)

    def listen(self) -> None:
        if self.processing is not None or self.outbox:
            return                                  # one event at a time; later ones wait in the FIFO
        event = self.hw.sound_event()
        if event is None:
            return
        direction, level = event
        if level < T.APU_MIN_LEVEL_DB:
            self.ignored += 1
            return
        self.heard += 1
        self.processing = event                     # seed 3.2.7: BUSY while processing audio
        self.hw.after(T.APU_PROCESS_S, self.found)

    def found(self) -> None:
        direction, level = self.processing  # type: ignore[misc]
        self.processing = None
        channel = int(round(direction)) % 360                # body frame, ccw from forward (spec XMIT_RECORD)
        value = max(0, min(255, int(round(level))))          # dB, clamped to the byte
        self.hw.note("sound_direction", direction_deg=channel, level_db=value)
        self.queue_record(M.XmitRecord(target=_NP3, source=self.address, kind=int(RecordKind.VALUE),
                                       channel=channel, value=value, age=age_byte(T.APU_PROCESS_S)))

    def status_ack(self) -> M.Message:
        """seed 3.2.7: BUSY while an event is processed and its record waits for the bus."""
        busy = self.processing is not None or bool(self.outbox)
        return M.StatusAckBusy(status=int(BusyStatus.BUSY if busy else BusyStatus.NOT_BUSY))

    def debug_metrics(self) -> ApuSdfDebug:
        return {"events_heard": self.heard, "events_too_quiet": self.ignored, "records_sent": self.records_sent}


class UicRcpDebug(TypedDict):
    """UIC_RCP.debug_metrics(): metrics.json `nodes.UIC/RCP`."""
    keys: int
    records_sent: int
    alerts: int
    commands: dict[str, int]        # command label -> times sent
    lcd: list[str]


class UIC_RCP(_Records, Runtime, UicRcpSkeleton):
    """seed 3.2.8, 4.1: the robot driven from a VT100 terminal on the RCP's RS-232 line; LCD and alerts."""

    def start(self) -> None:
        self._records_init()
        self.screen = Screen()
        self.decoder = KeyDecoder()
        self.keys = 0
        self.alerts = 0
        self.commands: dict[str, int] = {}
        self.hw.rcp_write(self.screen.full())
        self.every(T.UIC_KEY_POLL_S, self.poll_keys)

    def poll_keys(self) -> None:
        for key in self.decoder.feed(self.hw.rcp_read()):   # escape sequences read whole (behaviours.rcp_keys)
            self.key(key)

    def key(self, key: str) -> None:
        """seed 4.1: F=Forward, B=Backward, H=Halt, ... (behaviours.rcp_keys) -> a MOVE or POST_REQ record."""
        if key == _REDRAW:
            self.hw.rcp_write(self.screen.full())
            return
        msg = message_for_key(key)
        if msg is None:
            self.hw.rcp_write(self.screen.status_line(f"? key {key!r}: no command"))
            return
        self.keys += 1
        what = f"MOVE {MovCmd(msg.mov_cmd).name}" if isinstance(msg, M.Move) else msg.NAME
        self.commands[what] = self.commands.get(what, 0) + 1
        self.hw.note("rcp_key", key=key.upper(), command=what)
        self.hw.rcp_write(self.screen.status_line(f"{label_for_key(key)}: {what}"))
        self.queue_record(msg)

    def on_lcd_text(self, src: int, msg: M.LcdText) -> None:
        """seed 4.1: one line of the two-line LCD, mirrored on the terminal."""
        self.hw.rcp_write(self.screen.lcd_line(msg.line, msg.text.decode("latin-1")))

    def on_uic_alert(self, src: int, msg: M.UicAlert) -> None:
        """seed 3.2.17: BEEP -> the terminal's bell (piezo buzzer), BLINK -> blinking indicator (LED)."""
        self.alerts += 1
        self.hw.note("uic_alert", alert=int(msg.alert))
        self.hw.rcp_write(self.screen.alert_line(msg.alert))

    def status_ack(self) -> M.Message:
        """seed 3.2.8: BUSY while an operator command waits for the bus (CHOICE)."""
        return M.StatusAckBusy(status=int(BusyStatus.BUSY if self.outbox else BusyStatus.NOT_BUSY))

    def debug_metrics(self) -> UicRcpDebug:
        return {"keys": self.keys, "records_sent": self.records_sent, "alerts": self.alerts,
                "commands": dict(sorted(self.commands.items())), "lcd": [line.rstrip() for line in self.screen.lcd]}


class RLC(Runtime, RlcSkeleton):
    """seed 3.2.9: identification and status (the Runtime answers ID_REQ, STATUS_REQ NOT_BUSY). The radio host link
    is declared absent in spec/nodes.yaml (`absent`): the seed gives the modem no protocol to forward."""

