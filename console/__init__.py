"""The UIC/RCP remote console (seed 3.2.8, 4.1): drive the robot from a VT100 terminal.

"... über ein serielles Terminal oder ein anderes serielles VT100 kompatibles
Endgerät mit einfachen Befehlen (F=Forward, B=Backward, H=Halt, usw)
gesteuert" (seed 4.1). Three small parts:

  keymap    key -> message (MOVE with a Mov_Cmd, or POST_REQ); the key table
  screen    LCD lines, last command and alerts -> VT100 bytes
  terminal  Console: reads keys from a pty / own terminal / serial port, writes the screen

Interface for the UIC/RCP node behaviour (the simulator attaches one console):

    console = attach("pty")            # or "stdio", or a pyserial URL / device
    print("connect a terminal to", console.peer)
    ...
    for msg in console.poll():         # every control period: MOVE / POST_REQ to send (3.2.2:
        ...                            #   XMIT_REQ, then the record when the MCP grants the bus)
    console.handle(lcd_text_msg)       # on LCD_TEXT / UIC_ALERT from the MCP, or directly:
    console.show_lcd(0, "POST OK")     # line 0 or 1, 16 characters
    console.close()                    # restores the terminal

Try it without a robot: `python -m console` (keys in this terminal; Ctrl-C quits).
"""
from __future__ import annotations

from console.keymap import HELP, KEYMAP, label_for_key, message_for_key
from console.screen import Screen
from console.terminal import Console, FdPort, SerialPort, attach, open_pty

__all__ = ["Console", "Screen", "FdPort", "SerialPort", "attach", "open_pty", "KEYMAP", "HELP",
           "message_for_key", "label_for_key"]
