"""Plain-Python 2-D helpers (faster than numpy for a handful of points)."""
from __future__ import annotations

import math
from typing import Sequence

Pt = tuple[float, float]


def point_in_polygon(x: float, y: float, poly: Sequence[Pt]) -> bool:
    inside = False
    n = len(poly)
    x1, y1 = poly[-1]
    for i in range(n):
        x2, y2 = poly[i]
        if (y2 > y) != (y1 > y) and x < (x1 - x2) * (y - y2) / (y1 - y2) + x2:
            inside = not inside
        x1, y1 = x2, y2
    return inside


def to_world(pose: tuple[float, float, float], px: float, py: float) -> Pt:
    x, y, th = pose
    c, s = math.cos(th), math.sin(th)
    return (x + c * px - s * py, y + s * px + c * py)


def to_body(pose: tuple[float, float, float], wx: float, wy: float) -> Pt:
    x, y, th = pose
    c, s = math.cos(th), math.sin(th)
    dx, dy = wx - x, wy - y
    return (c * dx + s * dy, -s * dx + c * dy)


def rigid_fit(body_pts: Sequence[Pt], world_pts: Sequence[Pt]) -> tuple[float, float, float]:
    """Least-squares rigid transform (x, y, theta) mapping body_pts onto world_pts (2-D Procrustes)."""
    n = len(body_pts)
    bx = sum(p[0] for p in body_pts) / n
    by = sum(p[1] for p in body_pts) / n
    wx = sum(p[0] for p in world_pts) / n
    wy = sum(p[1] for p in world_pts) / n
    sxx = sxy = 0.0
    for (px, py), (qx, qy) in zip(body_pts, world_pts):
        px -= bx
        py -= by
        qx -= wx
        qy -= wy
        sxx += px * qx + py * qy
        sxy += px * qy - py * qx
    th = math.atan2(sxy, sxx) if n > 1 else 0.0
    c, s = math.cos(th), math.sin(th)
    return (wx - (c * bx - s * by), wy - (s * bx + c * by), th)


def seg_seg_distance(a: Pt, b: Pt, c: Pt, d: Pt) -> float:
    """Shortest distance between segments ab and cd."""
    if _segments_cross(a, b, c, d):
        return 0.0
    return min(_pt_seg(a, c, d), _pt_seg(b, c, d), _pt_seg(c, a, b), _pt_seg(d, a, b))


def _pt_seg(p: Pt, a: Pt, b: Pt) -> float:
    ax, ay = a
    dx, dy = b[0] - ax, b[1] - ay
    L = dx * dx + dy * dy
    t = 0.0 if L == 0 else max(0.0, min(1.0, ((p[0] - ax) * dx + (p[1] - ay) * dy) / L))
    return math.hypot(p[0] - ax - t * dx, p[1] - ay - t * dy)


def _orient(a: Pt, b: Pt, c: Pt) -> float:
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])


def _segments_cross(a: Pt, b: Pt, c: Pt, d: Pt) -> bool:
    d1, d2, d3, d4 = _orient(c, d, a), _orient(c, d, b), _orient(a, b, c), _orient(a, b, d)
    return d1 * d2 < 0 and d3 * d4 < 0


def convex_hull(points: Sequence[Pt]) -> list[Pt]:
    pts = sorted(set(points))
    if len(pts) <= 2:
        return pts
    lower: list[Pt] = []
    for p in pts:
        while len(lower) >= 2 and _orient(lower[-2], lower[-1], p) <= 0:
            lower.pop()
        lower.append(p)
    upper: list[Pt] = []
    for p in reversed(pts):
        while len(upper) >= 2 and _orient(upper[-2], upper[-1], p) <= 0:
            upper.pop()
        upper.append(p)
    return lower[:-1] + upper[:-1]


def inside_convex(x: float, y: float, hull: Sequence[Pt], margin: float = 0.0) -> bool:
    """True when (x, y) lies inside the CCW hull by at least `margin`."""
    if len(hull) < 3:
        return False
    for i in range(len(hull)):
        ax, ay = hull[i - 1]
        bx, by = hull[i]
        L = math.hypot(bx - ax, by - ay)
        if L == 0 or ((bx - ax) * (y - ay) - (by - ay) * (x - ax)) / L < margin:
            return False
    return True
