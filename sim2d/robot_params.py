"""Every physical number of the simulated robot, in one place.

The seed gives the mass (3.1.3), the leg structure (3.1.2) and ARACHNAE I's
gait (1.1); everything marked CHOICE is ours because the seed's figures
(Abb. 1-4) are missing. Units: metres, seconds, radians, kilograms, volts, amps.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field


@dataclass(frozen=True)
class RobotParams:
    mass_kg: float = 3.75                 # seed 3.1.3: "etwa 3.5 bis 4 kg"
    body_length: float = 0.30             # CHOICE (Abb. 1 missing)
    body_width: float = 0.16              # CHOICE
    body_height: float = 0.12             # CHOICE: top of body above ground when standing
    body_clearance: float = 0.07          # CHOICE: underside above ground; > step_limit so low obstacles pass under
    hip_height: float = 0.09              # CHOICE: hip joints above ground
    hip_x: tuple[float, ...] = (0.12, 0.0, -0.12)   # CHOICE: front, middle, rear hips (body frame)
    femur: float = 0.08                   # CHOICE: segment moved by servo 1
    tibia: float = 0.12                   # CHOICE: segment moved by servo 3
    neutral_reach: float = 0.12           # CHOICE: horizontal hip-to-foot distance at rest
    stroke: float = 0.08                  # seed 1.1: ARACHNAE I "maximaler Vorschub von 8 cm"
    lift: float = 0.03                    # seed 1.1: ARACHNAE I "maximaler Hub von 3 cm"
    speed: float = 0.10                   # seed 1.1: tripod gait "etwa 10 cm/sec"
    turn_stroke_rad: float = math.radians(20)  # CHOICE: body rotation per tripod half cycle
    servo_speed: float = 5.2              # CHOICE: rad/s, hobby servo 0.2 s / 60 deg
    servo_idle_a: float = 0.05            # CHOICE: servo current holding position
    servo_move_a: float = 0.35            # CHOICE: servo current while moving freely
    servo_stall_a: float = 1.8            # CHOICE: stall current when the leg is blocked (seed 6.1)
    electronics_a: float = 0.6            # CHOICE: 39 microcontrollers, sensors, transceivers
    battery_full_v: float = 5.0           # seed 3.2.17: battery window 4.2 .. 5.0 V
    battery_empty_v: float = 4.2          # seed 3.2.17
    battery_ah: float = 2.0               # CHOICE
    battery_r_ohm: float = 0.05           # CHOICE: internal resistance
    whisker_length: float = 0.10          # seed 1.2.2: tactile range "bis zu 10 cm"
    whisker_angle: float = math.radians(25)  # CHOICE: outward from the body axis
    ir_range: float = 0.10                # seed 3.2.13: "bis etwa 10 cm"
    ir_beams_deg: tuple[float, ...] = (15.0, 0.0, -15.0)   # seed 3.2.13: 0 deg and 15 deg either side
    us_range: float = 10.0                # seed 3.2.11: 10 m
    us_cone_deg: float = 15.0             # CHOICE: full beam width of a 40 kHz transducer
    us_cone_rays: int = 5                 # CHOICE: rays per ping across the cone
    us_noise_m: float = 0.02              # CHOICE: 1 sigma range noise
    ir_noise_m: float = 0.002             # CHOICE
    us_height: float = 0.14               # CHOICE: sonar head on top of the body
    ir_height: float = 0.06               # CHOICE: = step limit, so everything that blocks is seen
    whisker_height: float = 0.06          # CHOICE
    sound_speed: float = 343.0            # m/s, time of flight of a ping
    isc_step_deg: float = 3.0             # seed 3.2.14: resolution +-3 deg
    isc_max_deg: float = 60.0             # seed 3.2.14
    tsc_channels: int = 8                 # seed 3.2.15
    tsc_noise_c: float = 0.4              # CHOICE
    lsc_noise_rel: float = 0.03           # CHOICE: relative lux noise
    dt: float = 0.01                      # physics step (issue 4: fixed 10 ms)
    legs: tuple[int, ...] = field(default=(1, 2, 3, 4, 5, 6))

    @property
    def step_limit(self) -> float:
        """Highest obstacle a foot can step over: half the body height (seed 1.2.1)."""
        return self.body_height / 2

    @property
    def half_cycle(self) -> float:
        """Seconds per tripod half cycle so that one stroke per half cycle gives `speed`."""
        return self.stroke / self.speed

    def hip(self, leg: int) -> tuple[float, float]:
        """Hip position of leg 1..6 in the body frame (x forward, y left).

        CHOICE: legs 1-3 on the left, front to rear; 4-6 on the right, front to rear.
        """
        side = 1.0 if leg <= 3 else -1.0
        return (self.hip_x[(leg - 1) % 3], side * self.body_width / 2)

    def side(self, leg: int) -> float:
        return 1.0 if leg <= 3 else -1.0

    def neutral_foot(self, leg: int) -> tuple[float, float]:
        hx, hy = self.hip(leg)
        return (hx, hy + self.side(leg) * self.neutral_reach)

    def tripod_group(self, leg: int) -> int:
        """Legs 1,3,5 form tripod 0 and 2,4,6 tripod 1 (each a stable triangle)."""
        return 0 if leg in (1, 3, 5) else 1


DEFAULT = RobotParams()
