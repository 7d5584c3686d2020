"""RCP keys -> the messages the UIC/RCP sends (seed 4.1: "F=Forward, B=Backward, H=Halt, usw").

Pure data and one function, so the keys are documented in one table and the
terminal driver never decides anything itself. Keys are case-insensitive.

    F forward        B backward       H or space: halt (STOP)
    L turn left      R turn right
    Q sidestep left  E sidestep right   (the keys left and right of W on a QWERTY keyboard)
    1 tripod gait    2 ripple gait    3 wave gait
    P POST: run the power-on self test now (seed 6.3)
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

HELP = "F fwd B back H halt L/R turn Q/E side 1/2/3 gait P POST"


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
