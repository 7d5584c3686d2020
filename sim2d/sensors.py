"""Sensor physics: read the world around the robot, in physical units.

Each read is done only when a node asks (a ray cast per ping, never per
step). Readings carry the sensor's own noise and resolution; quantising
them into the spec's wire encodings is the sensor controller's firmware
(behaviours.sensors). Noise comes from a named stream per sensor (sim2d.rng).
"""
from __future__ import annotations

import math
import random
from dataclasses import dataclass, field

from behaviours.geometry import FeelerArm, mirrored
from sim2d.geometry import Pt, to_world
from sim2d.rng import stream
from sim2d.robot import Robot
from sim2d.world import World


@dataclass
class SensorLog:
    """What the renderer and the metrics want to show of the sensing."""

    sonar: list[tuple[float, Pt]] = field(default_factory=list)          # (t, echo point)
    ir_rays: list[tuple[Pt, Pt, bool]] = field(default_factory=list)     # last IR beams: start, end, hit
    ir_hits: list[tuple[Pt, Pt]] = field(default_factory=list)          # every beam that hit: start, echo point
    whisker_hits: list[tuple[float, Pt]] = field(default_factory=list)


class Sensors:
    def __init__(self, world: World, robot: Robot, seed: int):
        self.world, self.robot, self.p = world, robot, robot.p
        self.rng = {name: stream(seed, f"sensor:{name}") for name in ("usrc", "irrc", "tsc", "lsc", "isc", "psc")}
        self.log = SensorLog()
        self.seed = seed
        self.fault_noise: dict[str, float] = {}      # scenario sensor faults: extra 1-sigma spread per reading
        self.fault_rng: dict[str, random.Random] = {}

    def set_fault(self, name: str, noise: float) -> None:
        """A sensor fault (scenario `faults: - {sensor: IRRC, noise: 0.03}`); noise 0 ends it."""
        key = name.lower()
        self.fault_noise[key] = noise
        self.fault_rng.setdefault(key, stream(self.seed, f"fault:{key}"))

    def _extra(self, key: str) -> float:
        sigma = self.fault_noise.get(key, 0.0)
        return self.fault_rng[key].gauss(0.0, sigma) if sigma > 0 else 0.0

    def _faulty_range(self, key: str, hit: float | None, top: float) -> float | None:
        """A faulty range sensor also makes up echoes out of nothing: the spread applies to 'no echo' too."""
        if self.fault_noise.get(key, 0.0) <= 0:
            return hit
        d = (top if hit is None else hit) + self._extra(key)
        return None if d >= top else max(0.0, d)

    # seed 3.2.11: 40 kHz transducer on a head turning 360 deg in 1 deg steps, range 10 m
    def usrc_ping(self, head_deg: int, t: float = 0.0) -> tuple[float | None, float]:
        """Echo distance in m (None: no echo in range) and time of flight (s), head at `head_deg` (body frame)."""
        p = self.p
        x, y, th = self.robot.pose
        base = th + math.radians(head_deg % 360)
        n = p.us_cone_rays
        half = math.radians(p.us_cone_deg) / 2
        best: tuple[float, Pt] | None = None
        for i in range(n):
            a = base + (-half + 2 * half * i / (n - 1) if n > 1 else 0.0)
            hit = self.world.ray((x, y), a, p.us_range, p.us_height)
            if hit is not None and (best is None or hit[0] < best[0]):
                best = hit
        if best is None:
            return self._faulty_range("usrc", None, p.us_range), 2 * p.us_range / p.sound_speed
        d = max(0.0, best[0] + self.rng["usrc"].gauss(0.0, p.us_noise_m))
        self.log.sonar.append((t, best[1]))
        return self._faulty_range("usrc", d, p.us_range), 2 * best[0] / p.sound_speed

    # seed 3.2.13: three IR beams, 0 deg and +-15 deg, range 10 cm
    def irrc(self) -> tuple[float | None, ...]:
        """Distance in m of each beam (left, centre, right); None: nothing within range."""
        p = self.p
        th = self.robot.pose[2]
        origin = to_world(self.robot.pose, p.body_length / 2, 0.0)
        out, rays = [], []
        for deg in p.ir_beams_deg:
            a = th + math.radians(deg)
            hit = self.world.ray(origin, a, p.ir_range, p.ir_height)
            if hit is None:
                out.append(self._faulty_range("irrc", None, p.ir_range))
                rays.append((origin, (origin[0] + p.ir_range * math.cos(a), origin[1] + p.ir_range * math.sin(a)), False))
            else:
                d = max(0.0, hit[0] + self.rng["irrc"].gauss(0.0, p.ir_noise_m))
                out.append(self._faulty_range("irrc", d, p.ir_range))
                rays.append((origin, hit[1], True))
                self.log.ir_hits.append((origin, hit[1]))
        self.log.ir_rays = rays
        return tuple(out)

    # seed 3.2.12: two end switches at the head, left and right, each closed by its rigid feeler (seed 1.2.2)
    def whiskers(self, t: float = 0.0) -> tuple[bool, bool]:
        """(left, right): any arm of that side's feeler (robot_params.whisker_arms) meets an obstacle."""
        res = []
        for arms in (self.p.whisker_arms, mirrored(self.p.whisker_arms)):
            hit = self._feeler_hit(arms)
            if hit is not None:
                self.log.whisker_hits.append((t, hit[1]))
            res.append(hit is not None)
        return res[0], res[1]

    def _feeler_hit(self, arms: tuple[FeelerArm, ...]) -> tuple[float, Pt] | None:
        """The first obstacle at least whisker_height tall met by a wire of the feeler, segment by segment."""
        for arm in arms:
            for a, b in zip(arm, arm[1:]):
                start, end = to_world(self.robot.pose, a.x, a.y), to_world(self.robot.pose, b.x, b.y)
                hit = self.world.ray(start, math.atan2(end[1] - start[1], end[0] - start[0]),
                                     math.dist(start, end), self.p.whisker_height)
                if hit is not None:
                    return hit
        return None

    def foot_contact(self, leg: int) -> bool:
        """Sole switch (seed 1.2.2): no contact over a pit."""
        return self.robot.legs[leg].contact

    # seed 3.2.14: channel 0 longitudinal, 1 transverse, -60..60 deg, +-3 deg
    def isc(self) -> tuple[float, float]:
        """(longitudinal, transverse) degrees in the sensor's steps, within its range."""
        x, y, th = self.robot.pose
        ix, iy = self.world.incline(x, y)
        gx, gy = math.tan(math.radians(ix)), math.tan(math.radians(iy))
        pitch = math.degrees(math.atan(gx * math.cos(th) + gy * math.sin(th)))
        roll = math.degrees(math.atan(-gx * math.sin(th) + gy * math.cos(th)))
        r = self.rng["isc"]
        step, top = self.p.isc_step_deg, self.p.isc_max_deg

        def resolve(deg: float) -> float:
            return max(-top, min(top, step * round(deg / step)))
        return (resolve(pitch + r.gauss(0.0, step / 3) + self._extra("isc")),
                resolve(roll + r.gauss(0.0, step / 3) + self._extra("isc")))

    def tilt_deg(self) -> float:
        """True (noise-free) inclination magnitude under the body, for the metrics."""
        ix, iy = self.world.incline(self.robot.pose[0], self.robot.pose[1])
        return math.degrees(math.atan(math.hypot(math.tan(math.radians(ix)), math.tan(math.radians(iy)))))

    # seed 3.2.15: 8 channels, int8 degrees C, -20..100
    def tsc(self) -> tuple[float, ...]:
        """CHOICE: the 8 probes sit around the body rim at 45 degree steps, channel 0 at the front."""
        p = self.p
        out = []
        for ch in range(p.tsc_channels):
            a = 2 * math.pi * ch / p.tsc_channels
            px, py = to_world(self.robot.pose, p.body_length / 2 * math.cos(a), p.body_width / 2 * math.sin(a))
            out.append(self.world.temperature(px, py) + self.rng["tsc"].gauss(0.0, p.tsc_noise_c) + self._extra("tsc"))
        return tuple(out)

    # seed 3.2.16: logarithmic light sensor on top of the body
    def lsc(self) -> float:
        """Lux at the sensor."""
        lux = self.world.lux(self.robot.pose[0], self.robot.pose[1])
        return max(0.0, lux * (1.0 + self.rng["lsc"].gauss(0.0, self.p.lsc_noise_rel) + self._extra("lsc")))

    # seed 3.2.17: battery voltage
    def psc(self) -> float:
        """Battery volts."""
        return self.robot.battery_voltage() + self.rng["psc"].gauss(0.0, 0.005) + self._extra("psc")

    # seed 3.2.18: position (potentiometer), speed (tacho), plus motor current (seed 6.1)
    def joint(self, leg: int, joint: int) -> tuple[float, float, float]:
        j = self.robot.legs[leg].joints[joint - 1]
        return j.angle, j.speed, j.current
