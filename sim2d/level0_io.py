"""The simulated world of the level-0 peripherals: the RCP's RS-232 line and the SDF's microphones.

Why a module of its own: the operator (scenario `operator:` keys, or a real
terminal attached with `--console`) and the sound events (scenario
`sounds:`) are outside the robot; this is where they meet the UIC/RCP's and
the APU/SDF's boards (sim2d.hardware). The nodes decide everything; this
only moves bytes and physical readings.
"""
from __future__ import annotations

import math
import time
from collections import deque
from typing import TYPE_CHECKING, Any, Protocol

from sim2d.rng import stream

if TYPE_CHECKING:
    from sim2d.sim import Simulation

# CHOICE: the SDF's microphone array resolves a direction to within this many degrees (1 sigma) ...
SDF_NOISE_DEG = 4.0
# ... and the scenario's level_db is the source's level at 1 m, falling 6 dB per doubling of distance
SDF_REF_DISTANCE_M = 1.0
CONSOLE_POLL_S = 0.02      # a live terminal is read and the run paced to wall time every 20 ms (sim time)


class HostPort(Protocol):
    """A host-side terminal line (console.terminal.FdPort / SerialPort)."""

    def read(self, timeout: float = 0.0) -> bytes: ...

    def write(self, data: bytes) -> None: ...


class RcpLine:
    """The RS-232 line between the UIC/RCP and the operator's terminal (seed 3.2.8, 4.1).

    Keys typed (by the scenario or a live terminal) wait in `rx` until the
    node reads them; everything the node writes is kept in `screen` (the
    VT100 byte stream, for tests and logs) and copied to a live terminal.
    """

    def __init__(self) -> None:
        self.rx = bytearray()
        self.screen = bytearray()
        self.host: HostPort | None = None
        self.typed: list[tuple[float, bytes]] = []

    def type(self, t: float, keys: bytes) -> None:
        """The operator types `keys` at time t."""
        self.typed.append((t, keys))
        self.rx += keys

    def read(self) -> bytes:
        data, self.rx = bytes(self.rx), bytearray()
        return data

    def write(self, data: bytes) -> None:
        self.screen += data
        if self.host is not None:
            self.host.write(data)


class Microphones:
    """The SDF's view of the scenario's sound events: direction relative to the body, level at the robot."""

    def __init__(self, seed: int) -> None:
        self.rng = stream(seed, "sensor:sdf")
        self.pending: deque[tuple[float, float]] = deque()
        self.events: list[tuple[float, tuple[float, float]]] = []   # (t, source position) of every sound

    def hear(self, t: float, pose: tuple[float, float, float], pos: tuple[float, float], level_db: float) -> None:
        x, y, th = pose
        d = math.hypot(pos[0] - x, pos[1] - y)
        rel = math.degrees(math.atan2(pos[1] - y, pos[0] - x) - th) + self.rng.gauss(0.0, SDF_NOISE_DEG)
        level = level_db - 20 * math.log10(max(d, SDF_REF_DISTANCE_M) / SDF_REF_DISTANCE_M)
        self.events.append((t, pos))
        self.pending.append((rel % 360.0, level))

    def next(self) -> tuple[float, float] | None:
        return self.pending.popleft() if self.pending else None


def schedule(sim: "Simulation") -> None:
    """Put the scenario's operator keys and sound events on the simulation's clock."""
    sc = sim.scenario
    for o in sc.operator:
        sim.sched.at(o.at, lambda keys=o.keys.encode("ascii"): sim.rcp.type(sim.sched.now, keys))
    for s in sc.sounds:
        sim.sched.at(s.at, lambda s=s: sim.microphones.hear(sim.sched.now, sim.robot.pose, s.pos, s.level_db))


class WallClock:
    """No terminal: only keeps the run to the wall clock (`--pace` without `--console`)."""

    peer = None

    def read(self, timeout: float = 0.0) -> bytes:
        if timeout > 0:
            time.sleep(timeout)
        return b""

    def write(self, data: bytes) -> None:
        pass


QUIT_KEYS = (b"\x03", b"\x04")        # Ctrl-C, Ctrl-D on a raw terminal: end the run


def attach_console(sim: "Simulation", port: HostPort, pace: float = 1.0) -> None:
    """A live terminal on the RCP line: keys typed on it reach the UIC/RCP, the run is paced to wall time.

    `pace` is simulated seconds per wall second (1.0: real time). Every
    CONSOLE_POLL_S of simulated time the run waits for the wall clock, then
    reads what the operator typed meanwhile.
    """
    if pace <= 0:
        raise ValueError(f"pace {pace}: must be > 0")
    sim.rcp.host = port
    t0 = time.monotonic()

    def tick() -> None:
        ahead = sim.sched.now / pace - (time.monotonic() - t0)
        keys = port.read(max(0.0, ahead))        # wait for the wall clock, waking up for keys
        while keys:
            if any(q in keys for q in QUIT_KEYS):
                raise KeyboardInterrupt
            sim.rcp.type(sim.sched.now, keys)
            ahead = sim.sched.now / pace - (time.monotonic() - t0)
            keys = port.read(ahead) if ahead > 0 else b""
        sim.sched.after(CONSOLE_POLL_S, tick)
    sim.sched.at(0.0, tick)


def sound_metrics(sim: "Simulation") -> dict[str, Any]:
    """Sound events and how far the robot's final heading is from the last one (degrees, 0..180)."""
    mic = sim.microphones
    out: dict[str, Any] = {"events": len(mic.events), "final_heading_error_deg": None}
    if mic.events:
        x, y, th = sim.robot.pose
        _t, (sx, sy) = mic.events[-1]
        err = (math.degrees(math.atan2(sy - y, sx - x) - th) + 180.0) % 360.0 - 180.0
        out["final_heading_error_deg"] = round(abs(err), 2)
    return out


def rcp_metrics(sim: "Simulation") -> dict[str, Any]:
    """Keys the operator typed and how many bytes the UIC/RCP drew on the terminal."""
    return {"keys_typed": sum(len(k) for _t, k in sim.rcp.typed), "screen_bytes": len(sim.rcp.screen)}
