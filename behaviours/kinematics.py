"""Forward and inverse kinematics of one 3-DOF leg (seed 3.1.2/3.1.3), as the LCP computes them.

Joint numbering follows the servos of seed 3.1.3: joint 1 lifts the femur
(servo 1, carries the weight), joint 2 swings the whole leg horizontally
(servo 2, forward/backward), joint 3 is the knee (servo 3, the supporting
segment). Angles in radians; 0 for joint 2 points the leg straight outwards.
Foot positions are (body x, body y, height above ground).
"""
from __future__ import annotations

import math

from behaviours.geometry import RobotGeometry


def fk(p: RobotGeometry, leg: int, q1: float, q2: float, q3: float) -> tuple[float, float, float]:
    """Foot position (body x, body y, height above ground) for joint angles."""
    hx, hy = p.hip(leg)
    side = p.side(leg)
    reach = p.femur * math.cos(q1) + p.tibia * math.cos(q1 - q3)
    z = p.hip_height + p.femur * math.sin(q1) + p.tibia * math.sin(q1 - q3)
    return (hx + reach * math.sin(q2), hy + side * reach * math.cos(q2), z)


def ik(p: RobotGeometry, leg: int, fx: float, fy: float, fz: float) -> tuple[float, float, float]:
    """Joint angles putting the foot at (fx, fy, fz); unreachable targets are clamped to the workspace."""
    hx, hy = p.hip(leg)
    side = p.side(leg)
    dx, dy = fx - hx, side * (fy - hy)
    q2 = math.atan2(dx, dy)
    r = math.hypot(dx, dy)
    z = fz - p.hip_height
    L1, L2 = p.femur, p.tibia
    d = (r * r + z * z - L1 * L1 - L2 * L2) / (2 * L1 * L2)
    d = max(-1.0, min(1.0, d))
    q3 = math.acos(d)                        # knee bend, knee above the hip-foot line
    q1 = math.atan2(z, r) + math.atan2(L2 * math.sin(q3), L1 + L2 * math.cos(q3))
    return (q1, q2, q3)


def _smooth(u: float) -> float:
    """Smoothstep: 0 -> 1 with zero slope at both ends (no jerk at a phase change)."""
    u = 0.0 if u < 0.0 else 1.0 if u > 1.0 else u
    return u * u * (3.0 - 2.0 * u)


def swing_point(start: tuple[float, float, float], end: tuple[float, float], lift: float, s: float,
                edge: float) -> tuple[float, float, float]:
    """The foot at progress s (0..1) of a swing: lift-off, transfer, touch-down (seed 3.2.10 trajectories).

    The first `edge` of the swing lifts the foot straight up from `start` to `lift`, the middle
    carries it at that height to above `end`, the last `edge` lowers it straight down onto `end`
    (a foot neither drags over the ground nor lands with a horizontal speed). A swing that starts
    in the air (re-planned mid-swing) spends only the part of the lift phase it still needs.
    """
    x0, y0, z0 = start
    up = edge * max(0.0, lift - z0) / lift if lift > 0 else 0.0
    down = 1.0 - edge
    if s < up:
        return (x0, y0, z0 + (lift - z0) * _smooth(s / up))
    if s <= down:
        u = _smooth((s - up) / (down - up)) if down > up else 1.0
        return (x0 + (end[0] - x0) * u, y0 + (end[1] - y0) * u, max(z0, lift))
    return (end[0], end[1], max(z0, lift) * (1.0 - _smooth((s - down) / edge)))
