"""The UIC/RCP remote console (seed 3.2.8, 4.1): drive the robot from a VT100 terminal.

"... über ein serielles Terminal oder ein anderes serielles VT100 kompatibles
Endgerät mit einfachen Befehlen (F=Forward, B=Backward, H=Halt, usw)
gesteuert" (seed 4.1). The key table (behaviours.rcp_keys: key -> MOVE with a Mov_Cmd, or POST_REQ)
and the VT100 picture (behaviours.rcp_screen: LCD lines, last command, alerts -> bytes) are the UIC/RCP
node's own firmware logic, so they live in behaviours/ beside it (behaviours.level0.UIC_RCP). This
package is only the host's end of the RS-232 line (`terminal`: a pty, the own terminal or a serial
port), carrying bytes between a running simulation and the operator:

    arachnae sim run scenarios/console_drive.yaml --console pty        # prints /dev/pts/N
    arachnae sim run scenarios/console_drive.yaml --console stdio
    arachnae sim run scenarios/console_drive.yaml --console serial:/dev/ttyUSB0

`python -m console [stdio|pty|serial:DEV]`: an idle robot in an open room to drive by hand.
"""
from __future__ import annotations

from behaviours.rcp_keys import HELP, KEYMAP, KeyDecoder, label_for_key, message_for_key
from behaviours.rcp_screen import Screen

# console.terminal (termios, pyserial: host only) is imported where a line is opened, never by the firmware side
__all__ = ["Screen", "KEYMAP", "HELP", "KeyDecoder", "message_for_key", "label_for_key"]
