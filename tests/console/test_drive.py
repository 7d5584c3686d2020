"""The RCP console drives the robot in a RUNNING simulation (seed 4.1): keys typed on a pty move it.

The simulation runs paced to the wall clock with its UIC/RCP's RS-232 line on
a pseudo-terminal; the test is the operator: it opens the pty like a
terminal program, types F, H, L, H, 2 and P, and then measures what the robot
did around the MOVE records the UIC/RCP put on the first-level bus.
"""
from __future__ import annotations

import json
import math
import os
import select
import subprocess
import sys
import threading
import time
from pathlib import Path

from arachnae_proto import CodecError
from arachnae_proto.enums import MovCmd
from arachnae_proto.frame import parse
from arachnae_proto.messages import LcdText, Move, PostReq
from arachnae_proto.network import ADDRESS_OF
from behaviours.rcp_screen import LCD_COL, LCD_TOP_ROW, fit_lcd, goto
from console.terminal import attach

REPO = Path(__file__).resolve().parents[2]
PACE = 2.0          # simulated seconds per wall second
SCENARIO = """\
include: {arena}
name: console_pty
robot: {{pose: [2.5, 2.0, 0], task: idle}}
duration: {duration}
"""
UIC = ADDRESS_OF["UIC/RCP"]


def scenario(tmp_path: Path, duration: float) -> Path:
    p = tmp_path / "console_pty.yaml"
    p.write_text(SCENARIO.format(arena=REPO / "scenarios" / "common" / "arena.yaml", duration=duration))
    return p


class Terminal:
    """The operator's end of the pty: collects the screen, types keys at wall times after the start."""

    def __init__(self, device: str) -> None:
        self.fd = os.open(device, os.O_RDWR | os.O_NOCTTY)
        self.screen = b""

    def pump(self, seconds: float) -> None:
        end = time.monotonic() + seconds
        while (left := end - time.monotonic()) > 0:
            if select.select([self.fd], [], [], min(left, 0.05))[0]:
                try:
                    self.screen += os.read(self.fd, 4096)
                except OSError:
                    return

    def pump_until(self, marker: bytes, timeout: float) -> bool:
        """Read until `marker` is on the screen: an event the simulation shows, not a wall time (a loaded
        machine runs the paced simulation behind the clock)."""
        end = time.monotonic() + timeout
        while marker not in self.screen and time.monotonic() < end:
            self.pump(0.05)
        return marker in self.screen

    def type(self, keys: bytes) -> None:
        os.write(self.fd, keys)

    def close(self) -> None:
        os.close(self.fd)


def pose_at(poses: list, t: float) -> tuple[float, float, float]:
    """The logged pose nearest before simulated time t."""
    best = poses[0]
    for p in poses:
        if p[0] > t:
            break
        best = p
    return best[1], best[2], best[3]


def uic_records(frames: list) -> list[tuple[float, object]]:
    """(time, message) of every record the UIC/RCP put on the wire, decoded from the bytes."""
    out = []
    for f in frames:
        try:
            fr = parse(f.heard if f.heard is not None else f.sent)
        except CodecError:               # a collision on the wire: the record is resent, count the clean copy
            continue
        if fr.src == UIC and isinstance(fr.message, (Move, PostReq)):
            out.append((f.start, fr.message))
    return out


def test_keys_typed_on_the_pty_drive_the_running_simulation(tmp_path, spec):
    from sim2d import runner

    port = attach("pty")
    term = Terminal(port.peer)
    box: dict = {}
    wall0 = time.monotonic()
    sim = threading.Thread(target=lambda: box.update(out=runner.run(str(scenario(tmp_path, 13.0)), spec=spec,
                                                                    console=port, pace=PACE)))
    sim.start()
    try:
        # simulated time ~ PACE x wall time; POST is over after about 1.3 s simulated
        for at_sim, keys in ((2.0, b"F"), (5.5, b"h"), (6.5, b"L"), (9.5, b"H"), (10.0, b"2"), (10.5, b"P")):
            term.pump(wall0 + at_sim / PACE - time.monotonic())
            term.type(keys)
        sim.join(timeout=20)
        term.pump(0.2)
    finally:
        term.close()
        port.close()
    assert not sim.is_alive()
    wall = time.monotonic() - wall0
    # paced to the wall clock: never ahead of it. Behind it only when the machine is short of CPU (a paced
    # simulation cannot catch up), which the join's timeout above bounds; the keys' effects are checked below
    assert wall > 13.0 / PACE - 0.5
    out = box["out"]
    recs = uic_records(out.result.frames)
    kinds = [m.mov_cmd if isinstance(m, Move) else "POST" for _t, m in recs]
    assert kinds == [MovCmd.FORWARD, MovCmd.STOP, MovCmd.TURN_LEFT, MovCmd.STOP, MovCmd.RIPPLE, "POST"]
    t_f, t_h, t_l, t_h2 = (t for t, _m in recs[:4])
    poses = out.result.poses

    # F: the robot walks forward along its heading
    x0, y0, th0 = pose_at(poses, t_f)
    x1, y1, th1 = pose_at(poses, t_h)
    forward = (x1 - x0) * math.cos(th0) + (y1 - y0) * math.sin(th0)
    assert forward > 0.15, forward                                   # ~10 cm/s (seed 1.1) for ~3.5 s
    # H: stopped within a second, then it stays put until L
    xs, ys, ths = pose_at(poses, t_h + 1.0)
    xe, ye, the = pose_at(poses, t_l)
    assert math.hypot(xe - xs, ye - ys) < 0.005 and abs(the - ths) < 0.01
    # L: the heading turns counter-clockwise
    _x, _y, th2 = pose_at(poses, t_h2)
    turned = math.degrees(math.atan2(math.sin(th2 - th0), math.cos(th2 - th0)))
    assert turned > 15.0, turned
    print(f"F at {t_f:.2f} s: {forward:.3f} m forward; H at {t_h:.2f} s: drift {math.hypot(xe - xs, ye - ys):.4f} m; "
          f"L at {t_l:.2f} s: turned {turned:.1f} deg by {t_h2:.2f} s; wall {wall:.1f} s")
    # P: the MCP ran POST a second time (seed 6.3: POST can be started from the UIC/RCP)
    assert out.result.metrics["notes"]["post_verdict"]["count"] >= 2
    assert out.result.metrics["nodes"]["UIC/RCP"]["keys"] == 6

    # the terminal showed each command on the status line, and the LCD lines the MCP sent
    screen = term.screen
    assert b"UIC/RCP" in screen
    for text in (b"> forward: MOVE FORWARD", b"> halt: MOVE STOP", b"> turn left: MOVE TURN_LEFT",
                 b"> ripple gait: MOVE RIPPLE", b"> POST: POST_REQ"):
        assert text in screen, text
    lcd = [parse(f.sent).message for f in out.result.frames
           if f.sent[0] == UIC and isinstance(parse(f.sent).message, LcdText)]
    assert lcd                                                        # the MCP wrote the POST verdict (6.3)
    for m in lcd:
        drawn = goto(LCD_TOP_ROW + m.line, LCD_COL) + "\x1b[7m" + fit_lcd(m.text.decode("latin-1"))
        assert drawn.encode() in screen
    assert screen == out.rcp_screen[:len(screen)]                     # the node's bytes, unaltered


def test_cli_console_pty_prints_the_device_and_takes_keys(tmp_path):
    out_dir = tmp_path / "out"
    proc = subprocess.Popen([sys.executable, "-m", "arachnae.cli", "sim", "run", str(scenario(tmp_path, 6.0)),
                             "--console", "pty", "--pace", "3", "--out", str(out_dir)],
                            cwd=REPO, stdout=subprocess.PIPE, text=True)
    try:
        first = proc.stdout.readline()
        assert first.startswith("RCP console on /dev/"), first
        term = Terminal(first.split()[3].rstrip(":"))
        assert term.pump_until(b"POST OPERATIONAL", timeout=30)         # the MCP's LCD line: POST is done (6.3)
        term.type(b"F")
        term.pump(0.5)
        proc.wait(timeout=60)
        term.close()
    finally:
        proc.kill()
    assert proc.returncode == 0
    m = json.loads((out_dir / "metrics.json").read_text())
    assert m["rcp"]["keys_typed"] == 1 and m["nodes"]["UIC/RCP"]["commands"] == {"MOVE FORWARD": 1}
    assert m["displacement_m"] > 0.1                                   # walked forward for ~3 s
    assert (out_dir / "rcp_screen.vt100").read_bytes().count(b"MOVE FORWARD") == 1


def test_bad_console_or_pace_is_a_one_line_error(tmp_path, capsys):
    import pytest

    from arachnae.cli import main

    path = str(scenario(tmp_path, 1.0))
    assert main(["sim", "run", path, "--console", "bogus"]) == 1
    assert capsys.readouterr().err == "--console: expected pty, stdio or serial:DEVICE, got 'bogus'\n"
    with pytest.raises(SystemExit) as exc:          # a usage error: argparse's one line, exit 2
        main(["sim", "run", path, "--pace", "-2"])
    assert exc.value.code == 2
    assert capsys.readouterr().err.count("\n") == 1


def test_ctrl_c_typed_on_the_console_ends_the_run(tmp_path, spec):
    import pytest

    from sim2d import runner

    class Operator:
        peer = None
        keys = [b"", b"", b"\x03"]

        def read(self, timeout: float = 0.0) -> bytes:
            return self.keys.pop(0) if self.keys else b""

        def write(self, data: bytes) -> None:
            pass
    with pytest.raises(KeyboardInterrupt):
        runner.run(str(scenario(tmp_path, 5.0)), spec=spec, console=Operator(), pace=1000.0)
