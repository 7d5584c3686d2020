"""The SSC's speech logic (seed 3.2.6): resident messages, SPEAK's Repeat semantics, a log, optional WAV.

Why a separate, pure module: the SSC node behaviour only decodes frames; what
is said, how often and when is decided here with an injected clock, so it can
be tested without a bus and replayed after a run. espeak-ng stands in for the
SSI263 phoneme synthesizer when WAV files are wanted (seed 3.2.6: the
resident messages are English, so is the voice).

Semantics (seed 3.2.6):
  - Length 0 selects a resident message by index 1..10 (SPEAK_RESIDENT);
  - Repeat 0: the text is said again and again until a new string arrives;
  - Repeat 1..255: the text is said that many times (1 = once);
  - a new string takes over when the utterance being spoken ends (the
    synthesizer does not cut a phoneme string in the middle);
  - while an utterance is being spoken the SSC is BUSY (STATUS_ACK).
"""
from __future__ import annotations

import shutil
import subprocess
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from arachnae_proto import messages as M
from arachnae_proto.enums import SSC_MESSAGE_TEXTS, BusyStatus, SscMessage

Clock = Callable[[], float]

REPEAT_FOREVER = 0


def resident_text(index: int) -> str:
    """seed 3.2.6: the text of resident message `index` (1..10)."""
    try:
        return SSC_MESSAGE_TEXTS[SscMessage(index)]
    except ValueError:
        raise ValueError(f"no resident SSC message {index}; 1..{len(SSC_MESSAGE_TEXTS)}") from None


@dataclass(frozen=True)
class Voice:
    """SSI263 parameters from SETUP (register widths, spec SETUP), mapped onto espeak-ng's options."""

    rate: int = 8            # 0..15
    amplitude: int = 10      # 0..15
    inflection: int = 128    # 0..255
    articulation: int = 4    # 0..7 (no espeak-ng equivalent; kept for STATUS and the log)

    @property
    def words_per_minute(self) -> int:
        return 80 + 12 * self.rate           # 80..260 wpm; espeak-ng's default 175 is about rate 8

    @property
    def seconds_per_char(self) -> float:
        return 60.0 / (self.words_per_minute * 6)   # a word is about 6 characters with its space

    def espeak_args(self) -> list[str]:
        return ["-s", str(self.words_per_minute), "-a", str(round(self.amplitude * 200 / 15)),
                "-p", str(round(self.inflection * 99 / 255))]


@dataclass
class Utterance:
    """One saying of a text: when it started and ended, which repetition it was."""

    start: float
    end: float
    text: str
    resident: int | None     # index for resident messages, None for free text
    repetition: int          # 1 for the first saying
    wav: Path | None = None


@dataclass
class _Order:
    text: str
    resident: int | None
    repeat: int              # 0 = until a new string arrives
    said: int = 0
    wav: Path | None = None

    def again(self) -> bool:
        return self.repeat == REPEAT_FOREVER or self.said < self.repeat


class Speaker:
    """The SSC's speech state machine; call `advance()` (or any query) as time passes."""

    def __init__(self, clock: Clock, wav_dir: str | Path | None = None) -> None:
        self.clock = clock
        self.voice = Voice()
        self.wav_dir = Path(wav_dir) if wav_dir is not None else None
        self.log: list[Utterance] = []
        self.current: Utterance | None = None
        self.order: _Order | None = None      # what is being said, with its repeat count
        self.pending: _Order | None = None    # a new string waiting for the current utterance to end
        self.last_time = clock()

    # -- input: the SSC's messages (seed 3.2.6) ----------------------------------------
    def handle(self, msg: M.Message) -> None:
        """SETUP, SPEAK or SPEAK_RESIDENT as decoded by the generated codec."""
        if isinstance(msg, M.Setup):
            self.voice = Voice(msg.rate, msg.amplitude, msg.inflection, msg.articulation)
        elif isinstance(msg, M.Speak):
            self.speak(msg.text.decode("latin-1"), msg.repeat)
        elif isinstance(msg, M.SpeakResident):
            self.speak_resident(msg.index, msg.repeat)
        else:
            raise TypeError(f"the SSC does not speak {type(msg).__name__}")

    def speak(self, text: str, repeat: int = 1) -> None:
        """Say `text` `repeat` times (0: until a new string arrives)."""
        self._order(_Order(text, None, self._check_repeat(repeat)))

    def speak_resident(self, index: int, repeat: int = 1) -> None:
        """seed 3.2.6: Length 0 -> resident message by index."""
        self._order(_Order(resident_text(index), int(index), self._check_repeat(repeat)))

    @staticmethod
    def _check_repeat(repeat: int) -> int:
        if not 0 <= repeat <= 255:
            raise ValueError(f"Repeat {repeat}: 0..255 (seed 3.2.6)")
        return repeat

    def _order(self, order: _Order) -> None:
        self.advance()
        if self.current is None:
            self.order, self.pending = order, None
            self._start(self.clock())
        else:
            self.pending = order                   # a newer string replaces an older waiting one

    # -- time -------------------------------------------------------------------------
    def duration(self, text: str) -> float:
        return max(0.2, len(text) * self.voice.seconds_per_char)

    def _start(self, t: float) -> None:
        order = self.order
        assert order is not None
        order.said += 1
        if order.said == 1 and self.wav_dir is not None:
            order.wav = self.wav_dir / f"{len(self.log) + 1:03d}.wav"
            write_wav(order.text, order.wav, self.voice)
        self.current = Utterance(t, t + self.duration(order.text), order.text, order.resident, order.said, order.wav)
        self.log.append(self.current)

    def advance(self) -> None:
        """Finish utterances that ended by now and start what follows them, in order."""
        now = self.clock()
        self.last_time = now
        while self.current is not None and self.current.end <= now:
            end = self.current.end
            self.current = None
            if self.pending is not None:
                self.order, self.pending = self.pending, None
            elif self.order is not None and self.order.again():
                pass                                # say it again
            else:
                self.order = None
            if self.order is not None:
                self._start(end)

    @property
    def busy(self) -> BusyStatus:
        """seed 3.2.6: BUSY while speaking, for the SSC's STATUS_ACK."""
        self.advance()
        return BusyStatus.BUSY if self.current is not None else BusyStatus.NOT_BUSY

    def said(self) -> list[tuple[float, str]]:
        """(start time, text) of everything said (or begun) until now."""
        self.advance()
        return [(u.start, u.text) for u in self.log]


# --------------------------------------------------------------------------- WAV via espeak-ng
ESPEAK = "espeak-ng"


def espeak_available() -> bool:
    return shutil.which(ESPEAK) is not None


def write_wav(text: str, path: str | Path, voice: Voice | None = None) -> Path:
    """Synthesize `text` into a WAV file with espeak-ng (Debian package espeak-ng)."""
    exe = shutil.which(ESPEAK)
    if exe is None:
        raise FileNotFoundError("espeak-ng is not installed (Debian package espeak-ng)")
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    args = [exe, "-v", "en-us", *(voice or Voice()).espeak_args(), "-w", str(out), "--", text]
    subprocess.run(args, check=True, capture_output=True, timeout=30)
    return out


__all__ = ["Speaker", "Utterance", "Voice", "resident_text", "write_wav", "espeak_available", "REPEAT_FOREVER"]
