"""JAC (seed 3.2.18): its own position loop on potentiometer and tacho, and the JOINT_FEEDBACK flags."""
from __future__ import annotations

import math

import pytest

from arachnae_proto import messages as M
from arachnae_proto.enums import JointFlags

from behaviours import tuning as T
from behaviours.hardware import ServoState
from tests.behaviours.rig import Rig

LCP1, JAC11 = 0x21, 0x41                       # seed 3.2.18: JAC(1,1) on LCP(1)'s bus


class Servo:
    """A servo on the bench: the angle integrates the JAC's speed command (top speed 5 rad/s)."""

    def __init__(self, rig: Rig, stuck: bool = False) -> None:
        self.rig, self.stuck = rig, stuck
        self.angle, self.speed, self.current, self.temperature = 0.0, 0.0, 0.05, 20.0
        self.last = 0.0
        b = rig.board
        b.servo_state = self.state                       # type: ignore[method-assign]
        b.set_servo_drive = self.drive                   # type: ignore[method-assign]
        self.commands: list[float | None] = []

    def drive(self, speed: float | None) -> None:
        t = self.rig.board.t
        self.angle += self.speed * (t - self.last)
        self.last = t
        self.commands.append(speed)
        self.speed = 0.0 if speed is None or self.stuck else max(-5.0, min(5.0, speed))
        self.current = 1.8 if self.stuck and speed else 0.35 if self.speed else 0.05

    def state(self) -> ServoState:
        return ServoState(self.angle + self.speed * (self.rig.board.t - self.last), self.speed, self.current, self.temperature)


def feedback(rig: Rig, at: float) -> M.JointFeedback:
    rig.inject(at, LCP1, M.JointPoll())
    rig.run(at + 0.02)
    return rig.frames(M.JointFeedback)[-1][1].message


def target(rig: Rig, at: float, deg: float, deg_s: float) -> None:
    rig.inject(at, LCP1, M.JointTarget.from_phys(angle=deg, speed=deg_s))


def test_position_loop_reaches_the_target_at_the_commanded_speed(spec):
    rig = Rig(spec, "JAC", JAC11)
    servo = Servo(rig)
    target(rig, 0.1, 30.0, 60.0)                         # 30 degrees at 60 deg/s: half a second
    rig.run(0.35)
    assert max(abs(c) for c in servo.commands if c is not None) == pytest.approx(math.radians(60), rel=1e-6)
    assert math.degrees(servo.state().angle) == pytest.approx(15.0, abs=1.5)   # speed-limited, not a jump
    fb = feedback(rig, 0.9)
    assert fb.phys()["angle"] == pytest.approx(30.0, abs=0.2)
    assert fb.flags & JointFlags.AT_TARGET and not fb.flags & JointFlags.STALLED
    target(rig, 1.0, -10.0, 600.0)                       # P control: fast but converging, and backwards too
    rig.run(1.3)
    assert math.degrees(servo.state().angle) == pytest.approx(-10.0, abs=0.2)


def test_a_stuck_joint_is_stalled_and_overcurrent(spec):
    rig = Rig(spec, "JAC", JAC11)
    Servo(rig, stuck=True)
    target(rig, 0.1, 30.0, 60.0)
    fb = feedback(rig, 0.4)
    assert fb.flags & JointFlags.STALLED and fb.flags & JointFlags.OVERCURRENT     # tacho 0 while driven (6.1)
    assert fb.current == 1800 and not fb.flags & JointFlags.AT_TARGET


def test_overtemperature_flag_has_hysteresis_and_reports_the_winding_temperature(spec):
    rig = Rig(spec, "JAC", JAC11)
    servo = Servo(rig)
    servo.temperature = T.JAC_OVERTEMP_C + 1
    fb = feedback(rig, 0.2)
    assert fb.flags & JointFlags.OVERTEMP and fb.temperature == round(T.JAC_OVERTEMP_C + 1)
    servo.temperature = T.JAC_OVERTEMP_C - T.JAC_OVERTEMP_HYST_C / 2      # cooler, but within the hysteresis
    assert feedback(rig, 0.4).flags & JointFlags.OVERTEMP
    servo.temperature = T.JAC_OVERTEMP_C - T.JAC_OVERTEMP_HYST_C - 1
    assert not feedback(rig, 0.6).flags & JointFlags.OVERTEMP


def test_without_set_points_the_servo_goes_limp(spec):
    rig = Rig(spec, "JAC", JAC11)
    servo = Servo(rig)
    target(rig, 0.1, 5.0, 60.0)
    rig.run(0.1 + T.JAC_WATCHDOG_S - 0.05)
    assert None not in servo.commands                    # still holding while set points may come
    rig.run(0.1 + T.JAC_WATCHDOG_S + 0.05)
    assert servo.commands[-1] is None                    # the LCP is gone: no pulses (CHOICE)
    target(rig, 1.5, 5.0, 60.0)                          # a set point again: it drives again
    rig.run(1.6)
    assert servo.commands[-1] is not None
