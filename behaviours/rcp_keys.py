"""RCP keys -> the messages the UIC/RCP sends (seed 4.1: "F=Forward, B=Backward, H=Halt, usw").

Pure data and one function, so the keys are documented in one table and the
terminal driver never decides anything itself. Keys are case-insensitive.

    F forward        B backward       H or space: halt (STOP)
    L turn left      R turn right
    Q sidestep left  E sidestep right   (the keys left and right of W on a QWERTY keyboard)
    1 tripod gait    2 ripple gait    3 wave gait
    P POST: run the power-on self test now (seed 6.3)
    arrow keys: up F, down B, left L, right R

A terminal sends special keys as escape sequences (ESC [ A for the up arrow, ESC O P
for F1, ...). KeyDecoder reads them as whole sequences, so no byte inside one (the
'B' of the down arrow, the 'P' of F1) is ever taken for a command key.
"""
from __future__ import annotations

from arachnae_proto import messages as M
from arachnae_proto.enums import MovCmd

KEYMAP: dict[str, tuple[str, MovCmd | None]] = {
    # key: (label, Mov_Cmd; None = POST_REQ)
    "F": ("forward", MovCmd.FORWARD),          # seed 4.1: F = Forward
    "B": ("backward", MovCmd.BACKWARD),        # seed 4.1: B = Backward
    "H": ("halt", MovCmd.STOP),                # seed 4.1: H = Halt
    " ": ("halt", MovCmd.STOP),                # the big key stops too
    "L": ("turn left", MovCmd.TURN_LEFT),      # seed 3.2.3 Mov_Cmd values
    "R": ("turn right", MovCmd.TURN_RIGHT),
    "Q": ("sidestep left", MovCmd.SIDESTEP_LEFT),
    "E": ("sidestep right", MovCmd.SIDESTEP_RIGHT),
    "1": ("tripod gait", MovCmd.TRIPOD),
    "2": ("ripple gait", MovCmd.RIPPLE),
    "3": ("wave gait", MovCmd.WAVE),
    "P": ("POST", None),                       # seed 6.3: POST can be started from the UIC/RCP
}

HELP = "F fwd B back H halt L/R turn Q/E side 1/2/3 gait P POST; arrows"


ESC, CSI_START, SS3_START = 0x1B, ord("["), ord("O")
ARROWS = {"A": "F", "B": "B", "C": "R", "D": "L"}   # final byte of CSI/SS3 arrow -> key (up, down, right, left)


class KeyDecoder:
    """Bytes from a VT100 terminal -> keys (one character each), across reads.

    Printable ASCII and control characters are keys. ESC starts a sequence: CSI (ESC [ params
    intermediates final, ECMA-48), SS3 (ESC O final) or a two-byte escape (ESC x: Alt-x). Arrow
    keys become F/B/L/R (with or without modifier parameters); every other sequence is dropped
    whole, however long. A sequence cut between two reads continues with the next read. Bytes
    >= 0x80 (UTF-8 text, 8-bit controls) are not keys: the RCP's keys are ASCII.
    """

    _TEXT, _ESC, _CSI, _SS3 = range(4)

    def __init__(self) -> None:
        self.state = self._TEXT

    def feed(self, data: bytes) -> list[str]:
        keys: list[str] = []
        for byte in data:
            key = self._step(byte)
            if key is not None:
                keys.append(key)
        return keys

    def _step(self, byte: int) -> str | None:
        state = self.state
        if byte == ESC:                     # always (re)starts a sequence: a stray ESC only ever eats itself
            self.state = self._ESC
            return None
        if state == self._TEXT:
            return chr(byte) if byte < 0x80 else None
        if byte >= 0x80 or byte < 0x20:     # not part of any sequence: drop the sequence and this byte
            self.state = self._TEXT
            return None
        if state == self._ESC:
            self.state = {CSI_START: self._CSI, SS3_START: self._SS3}.get(byte, self._TEXT)   # else ESC x: Alt-x
            return None
        if state == self._SS3 or 0x40 <= byte <= 0x7E:   # SS3 takes one byte; CSI ends at its final byte
            self.state = self._TEXT
            return ARROWS.get(chr(byte))
        return None                         # CSI parameter (0x30-0x3F) or intermediate (0x20-0x2F) byte


def message_for_key(key: str) -> M.Message | None:
    """The message a key sends (MOVE or POST_REQ), or None for a key without a binding."""
    binding = KEYMAP.get(key.upper())
    if binding is None:
        return None
    _label, cmd = binding
    return M.PostReq() if cmd is None else M.Move(mov_cmd=int(cmd), param=0)


def label_for_key(key: str) -> str | None:
    binding = KEYMAP.get(key.upper())
    return binding[0] if binding else None
