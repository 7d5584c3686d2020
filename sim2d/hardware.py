"""One node's board in the simulation: the behaviours.hardware.Hardware interface.

Timers run on the simulation's scheduler and die with the node; frames go
to the node's bus ports; sensors and servos are the simulated physics
(sim2d.sensors, sim2d.robot). A killed node neither hears, talks nor times.
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any, Callable

from behaviours.hardware import ServoState
from sim2d.bus import Port

if TYPE_CHECKING:
    from sim2d.sim import Simulation


class NodeHardware:
    def __init__(self, sim: "Simulation", node: Any) -> None:
        self.sim, self.node = sim, node
        self.sched = sim.sched
        self.sensors = sim.sensors
        self.robot = sim.robot
        self.alive = True
        self.ports: dict[str, Port] = {}
        self.leg, self.joint = node.leg, node.joint

    # --- clock, timers, line -----------------------------------------------------------
    def now(self) -> float:
        return self.sched.now

    def after(self, delay: float, fn: Callable[..., Any], *args: Any) -> None:
        self.sched.after(delay, self._fire, fn, args)

    def _fire(self, fn: Callable[..., Any], args: tuple) -> None:
        if self.alive:
            fn(*args)

    def transmit(self, bus: str, data: bytes, driven_at: float | None = None) -> None:
        """The skeleton's transport: bytes onto the bus, never objects (driven_at: sim2d.bus.Port.send)."""
        if self.alive:
            self.ports[bus].send(data, driven_at)

    def line_idle_s(self, bus: str) -> float:
        return self.ports[bus].bus.idle_for(self.node.short)

    def note(self, event: str, **data: Any) -> None:
        self.sim.on_note(self.node, event, data)

    # --- sensors -------------------------------------------------------------------------
    def sonar_ping(self, head_deg: int) -> tuple[float | None, float]:
        return self.sensors.usrc_ping(head_deg, self.sched.now)

    def ir_ranges(self) -> tuple[float | None, ...]:
        return self.sensors.irrc()

    def whiskers(self) -> tuple[bool, bool]:
        return self.sensors.whiskers(self.sched.now)

    def inclination(self) -> tuple[float, float]:
        return self.sensors.isc()

    def temperatures(self) -> tuple[float, ...]:
        return self.sensors.tsc()

    def light(self) -> float:
        return self.sensors.lsc()

    def battery(self) -> float:
        return self.sensors.psc()

    def sole_contact(self) -> bool:
        return self.sensors.foot_contact(self.leg)

    # --- level-0 peripherals (sim2d.level0_io) ---------------------------------------------
    def rcp_read(self) -> bytes:
        return self.sim.rcp.read()

    def rcp_write(self, data: bytes) -> None:
        if self.alive:
            self.sim.rcp.write(data)

    def sound_event(self) -> tuple[float, float] | None:
        return self.sim.microphones.next()

    # --- servo ---------------------------------------------------------------------------
    def set_servo_drive(self, speed: float | None) -> None:
        if self.alive:
            self.robot.set_joint_drive(self.leg, self.joint, speed)

    def servo_state(self) -> ServoState:
        j = self.robot.legs[self.leg].joints[self.joint - 1]
        return ServoState(j.angle, j.speed, j.current, j.temperature)
