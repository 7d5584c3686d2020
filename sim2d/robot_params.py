"""Every physical number of the simulated robot, in one place.

The leg geometry and gait stroke are the firmware's own numbers
(behaviours.geometry.RobotGeometry, which this class extends), so the
simulated body and the MMC/LCP code cannot disagree. Added here: what only
physics needs. The seed gives the mass (3.1.3); everything marked CHOICE is
ours because the seed's figures (Abb. 1-4) are missing. Units: metres,
seconds, radians, kilograms, volts, amps.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from behaviours.geometry import BodyPoint, FeelerArm, RobotGeometry


@dataclass(frozen=True)
class RobotParams(RobotGeometry):
    mass_kg: float = 3.75                 # seed 3.1.3: "etwa 3.5 bis 4 kg"
    body_length: float = 0.30             # CHOICE (Abb. 1 missing)
    body_clearance: float = 0.07          # CHOICE: underside above ground; > step_limit so low obstacles pass under
    servo_speed: float = 5.2              # CHOICE: rad/s, hobby servo 0.2 s / 60 deg
    servo_idle_a: float = 0.05            # CHOICE: servo current holding position
    servo_move_a: float = 0.35            # CHOICE: servo current while moving freely
    servo_stall_a: float = 1.8            # CHOICE: stall current when the leg is blocked (seed 6.1)
    servo_winding_ohm: float = 5.0        # CHOICE: motor winding resistance (heat = I^2 R)
    servo_thermal_k_per_w: float = 15.0   # CHOICE: winding-to-air thermal resistance: moving (0.35 A) +9 K, stalled +240 K
    servo_thermal_tau_s: float = 60.0     # CHOICE: thermal time constant: a stalled servo passes 70 C in about 14 s
    electronics_a: float = 0.6            # CHOICE: 39 microcontrollers, sensors, transceivers
    battery_full_v: float = 5.0           # seed 3.2.17: battery window 4.2 .. 5.0 V
    battery_empty_v: float = 4.2          # seed 3.2.17
    battery_ah: float = 2.0               # CHOICE
    battery_r_ohm: float = 0.05           # CHOICE: internal resistance
    # seed 1.2.2: rigid feelers for the near field "bis zu 10 cm", one end switch per side (3.2.12). CHOICE (their
    # shape is not given; docs/decisions.md D18): the left feeler, rooted at the body's front corner, is a fork
    # of three wires, each at most 11 cm long. The outer arm, straight, 10 cm at 25 deg outward, sweeps 8-12.2 cm
    # beside the axis up to 9 cm ahead of the face (a post there is felt while the body can still turn off it:
    # posts_turn); the side arm, straight, 11 cm at 62 deg outward, sweeps 8-17.7 cm: a turn on the spot sweeps
    # the body's sides out to its corners' circle (17 cm round the centre), so a post walked past closer than
    # that is met by the next turn (posts_field seed 11 without it: a post 15 cm out, 17 contacts); the inner
    # arm runs 4.5 cm forward along
    # the side line, then bends inward across the body's lane to 1.5 cm beside the axis, 4.5 cm ahead of the
    # front face: a thin post there is touched with room to stop (the TPSC's STOP takes 3.3 cm). The right
    # feeler is its mirror image (geometry.mirrored).
    whisker_arms: tuple[FeelerArm, ...] = (
        (BodyPoint(0.15, 0.08), BodyPoint(0.15 + 0.10 * math.cos(math.radians(25)),
                                          0.08 + 0.10 * math.sin(math.radians(25)))),
        (BodyPoint(0.15, 0.08), BodyPoint(0.15 + 0.11 * math.cos(math.radians(62)),
                                          0.08 + 0.11 * math.sin(math.radians(62)))),
        (BodyPoint(0.15, 0.08), BodyPoint(0.195, 0.08), BodyPoint(0.195, 0.015)),
    )
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


DEFAULT = RobotParams()
