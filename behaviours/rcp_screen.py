"""The console's VT100 picture: the UIC's two-line LCD (16 characters each) and a status line.

Why VT100 bytes rather than curses: the RCP talks to "a serial terminal or
any other VT100-compatible device" (seed 4.1), so the output is plain
escape sequences that any such terminal (or a pty, or a test) can read.
Layout, 1-based rows and columns as VT100 counts them:

    row 1   ARACHNAE II  UIC/RCP
    row 3   +----------------+
    row 4   |<LCD line 0>    |      LCD text starts at column 2
    row 5   |<LCD line 1>    |
    row 6   +----------------+
    row 8   > <last command sent>
    row 9   ! <alert: BEEP / BLINK>
    row 11  <key help>
"""
from __future__ import annotations

from arachnae_proto.enums import Alert

from behaviours.rcp_keys import HELP

ESC = "\x1b"
LCD_COLS, LCD_ROWS = 16, 2
LCD_TOP_ROW, LCD_COL = 4, 2
STATUS_ROW, ALERT_ROW, HELP_ROW = 8, 9, 11
BELL = "\x07"


def goto(row: int, col: int) -> str:
    """VT100 CUP: cursor to row, col (1-based)."""
    return f"{ESC}[{row};{col}H"


CLEAR_SCREEN = f"{ESC}[2J"
CLEAR_LINE = f"{ESC}[2K"          # erase the whole line the cursor is on
REVERSE, NORMAL = f"{ESC}[7m", f"{ESC}[0m"


def printable(text: str) -> str:
    """Printable ASCII only (anything else, e.g. a key the operator typed, shows as '?'): the terminal is VT100."""
    return "".join(c if " " <= c <= "~" else "?" for c in text)


def fit_lcd(text: str) -> str:
    """An LCD line: printable ASCII, cut or padded to 16 characters (the HD44780-style display)."""
    return printable(text)[:LCD_COLS].ljust(LCD_COLS)


class Screen:
    """What the terminal shows; each method returns the bytes that bring the terminal up to date."""

    def __init__(self) -> None:
        self.lcd = [" " * LCD_COLS] * LCD_ROWS
        self.status = ""
        self.alert = 0

    def full(self) -> bytes:
        border = "+" + "-" * LCD_COLS + "+"
        parts = [CLEAR_SCREEN, goto(1, 1), "ARACHNAE II  UIC/RCP",
                 goto(LCD_TOP_ROW - 1, 1), border, goto(LCD_TOP_ROW + LCD_ROWS, 1), border]
        for row in range(LCD_ROWS):
            parts += [goto(LCD_TOP_ROW + row, 1), "|", goto(LCD_TOP_ROW + row, LCD_COL + LCD_COLS), "|"]
        out = "".join(parts).encode("ascii")
        out += b"".join(self.lcd_line(r, self.lcd[r]) for r in range(LCD_ROWS))
        out += self.status_line(self.status) + self._alert_bytes(self.alert, bell=False)
        return out + (goto(HELP_ROW, 1) + CLEAR_LINE + HELP).encode("ascii")

    def lcd_line(self, line: int, text: str) -> bytes:
        """seed 4.1: one LCD line (LCD_TEXT), drawn in reverse video inside the frame."""
        if line not in range(LCD_ROWS):
            raise ValueError(f"LCD line {line}: 0..{LCD_ROWS - 1}")
        self.lcd[line] = fit_lcd(text)
        return (goto(LCD_TOP_ROW + line, LCD_COL) + REVERSE + self.lcd[line] + NORMAL).encode("ascii")

    def status_line(self, text: str) -> bytes:
        self.status = printable(text)
        return (goto(STATUS_ROW, 1) + CLEAR_LINE + ("> " + self.status if text else "")).encode("ascii")

    def alert_line(self, flags: int) -> bytes:
        """seed 3.2.17: BEEP rings the terminal's bell (the piezo buzzer), BLINK shows blinking text."""
        self.alert = flags
        return self._alert_bytes(flags, bell=True)

    def _alert_bytes(self, flags: int, bell: bool) -> bytes:
        names = [a.name for a in Alert if a & flags]
        text = goto(ALERT_ROW, 1) + CLEAR_LINE
        if names:
            blink = f"{ESC}[5m" if flags & Alert.BLINK else ""
            text += f"{blink}! {' '.join(n for n in names if n)}{NORMAL}"
            if bell and flags & Alert.BEEP:
                text += BELL
        return text.encode("ascii")
