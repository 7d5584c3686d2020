"""The narrow interface between node firmware and the board it runs on.

Behaviours reach the clock, timers, the RS-485 line state, their sensors and
actuators only through an object with these methods; the simulator supplies
one per node (sim2d.hardware), real boards would supply their drivers. All
readings are physical units: the firmware quantises them into the spec's
wire encodings itself (behaviours.units).
"""
from __future__ import annotations

from typing import Any, Callable, NamedTuple, Protocol


class ServoState(NamedTuple):
    """seed 3.2.18: potentiometer, tacho generator, motor current, servo temperature."""

    angle: float        # rad
    speed: float        # rad/s
    current: float      # A
    temperature: float  # degrees C


class Hardware(Protocol):
    # -- clock, timers, line (every node) ---------------------------------------------
    def now(self) -> float:
        """Seconds since power-on."""

    def after(self, delay: float, fn: Callable[..., Any], *args: Any) -> None:
        """Call fn(*args) once, `delay` seconds from now (a hardware timer)."""

    def line_idle_s(self, bus: str) -> float:
        """Seconds the line `bus` has been idle; 0.0 while a frame is on it (UART idle-line timer)."""

    def note(self, event: str, **data: Any) -> None:
        """Telemetry on the debug port (POST verdict, reflexes); no effect on behaviour."""

    # -- sensors: each node calls only what its board has -----------------------------
    def sonar_ping(self, head_deg: int) -> tuple[float | None, float]:
        """USRC: echo distance in m (None: no echo within range) and the ping's time of flight in s."""

    def ir_ranges(self) -> tuple[float | None, ...]:
        """IRRC: distance in m of each beam (left, centre, right); None: nothing in range."""

    def whiskers(self) -> tuple[bool, bool]:
        """TPSC: (left, right) whisker touching."""

    def inclination(self) -> tuple[float, float]:
        """ISC: (longitudinal, transverse) degrees as the sensor resolves them."""

    def temperatures(self) -> tuple[float, ...]:
        """TSC: degrees C of each probe, channel order."""

    def light(self) -> float:
        """LSC: lux."""

    def battery(self) -> float:
        """PSC: battery volts."""

    def sole_contact(self) -> bool:
        """LCP: the sole switch of its foot (seed 1.2.2)."""

    # -- level-0 peripherals (seed 3.2.7, 3.2.8) ------------------------------------------
    def rcp_read(self) -> bytes:
        """UIC/RCP: bytes the operator's VT100 terminal sent on the RS-232 line since the last read (UART FIFO)."""

    def rcp_write(self, data: bytes) -> None:
        """UIC/RCP: bytes to the terminal on the RS-232 line (VT100 escape sequences)."""

    def sound_event(self) -> tuple[float, float] | None:
        """APU/SDF: the oldest sound event not yet read: (direction in degrees, body frame, counter-clockwise
        from forward; level in dB at the microphones), or None when nothing was heard."""

    # -- servo (JAC) ----------------------------------------------------------------------
    def set_servo_drive(self, speed: float | None) -> None:
        """JAC: the servo's output stage: turn at `speed` rad/s (signed; the JAC closes the position loop);
        None stops the pulses and the servo goes limp."""

    def servo_state(self) -> ServoState:
        """JAC: the servo's feedback."""
