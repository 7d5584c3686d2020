"""The robot's surroundings: solid geometry in pymunk plus the ground and the fields.

Walls and obstacles are pymunk shapes so rays and the body's collision use
pymunk's queries; pits, slopes, light and heat are fields evaluated at a point.
Light and heat zones have no shape, so they can never stop a range ray.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import pymunk

from sim2d.geometry import WALL_HEIGHT, WALL_RADIUS, Pt, convex_parts, point_in_polygon, seg_seg_distance
from sim2d.scenario import Scenario

WALL = 0b001
OBSTACLE = 0b010
BODY = 0b100
SOLID = pymunk.ShapeFilter(mask=WALL | OBSTACLE)
WALL_ONLY = pymunk.ShapeFilter(mask=WALL)


class SolidHit(NamedTuple):
    """A wall or obstacle at a point: its height, the point's depth inside its footprint (0: outside) and the
    outward normal of the face it is measured from (a foot pressed into that face slides along it)."""
    height: float
    depth: float
    normal: Pt = (0.0, 0.0)


def _bbox(poly: tuple[Pt, ...]) -> tuple[float, float, float, float]:
    xs, ys = [p[0] for p in poly], [p[1] for p in poly]
    return min(xs), min(ys), max(xs), max(ys)


class World:
    def __init__(self, scenario: Scenario):
        self.scenario = scenario
        self.space = pymunk.Space()
        self.heights: dict[pymunk.Shape, float] = {}
        self.segments: list[tuple[Pt, Pt, float]] = []   # (a, b, height) for clearance
        walls = list(scenario.walls)
        if scenario.boundary_walls:
            w, h = scenario.size
            walls.append(((0.0, 0.0), (w, 0.0), (w, h), (0.0, h), (0.0, 0.0)))
        for line in walls:
            for a, b in zip(line, line[1:]):
                seg = pymunk.Segment(self.space.static_body, a, b, WALL_RADIUS)
                seg.filter = pymunk.ShapeFilter(categories=WALL)
                self.space.add(seg)
                self.heights[seg] = WALL_HEIGHT
                self.segments.append((a, b, WALL_HEIGHT))
        # fast paths for the physics step: what can a foot above the floor meet?
        self.max_ground = max((ob.height for ob in scenario.obstacles), default=0.0)
        self.has_solids = bool(walls or scenario.obstacles)
        self.ground_boxes = [_bbox(p) for p in scenario.pits] + [_bbox(ob.polygon) for ob in scenario.obstacles]
        for ob in scenario.obstacles:
            for part in convex_parts(ob.polygon):   # pymunk would take a concave polygon's convex hull
                poly = pymunk.Poly(self.space.static_body, list(part))
                poly.filter = pymunk.ShapeFilter(categories=OBSTACLE)
                self.space.add(poly)
                self.heights[poly] = ob.height
            pts = ob.polygon
            for i in range(len(pts)):
                self.segments.append((pts[i - 1], pts[i], ob.height))

    def near(self, x: float, y: float, r: float) -> tuple[bool, bool]:
        """(a wall or obstacle, a pit or obstacle footprint) within r of (x, y): lets the physics skip queries."""
        solid = bool(self.space.bb_query(pymunk.BB(x - r, y - r, x + r, y + r), SOLID))
        ground = any(x0 - r <= x <= x1 + r and y0 - r <= y <= y1 + r for x0, y0, x1, y1 in self.ground_boxes)
        return solid, ground

    # --- rays -------------------------------------------------------------
    def ray(self, origin: Pt, angle: float, max_range: float, height: float) -> tuple[float, Pt] | None:
        """Distance and point of the first wall/obstacle at least `height` tall along the ray."""
        end = (origin[0] + max_range * math.cos(angle), origin[1] + max_range * math.sin(angle))
        best: tuple[float, Pt] | None = None
        for hit in self.space.segment_query(origin, end, 0.0, SOLID):
            if self.heights.get(hit.shape, 0.0) >= height:
                d = hit.alpha * max_range
                if best is None or d < best[0]:
                    best = (d, (hit.point.x, hit.point.y))
        return best

    # --- ground -----------------------------------------------------------
    def ground_height(self, x: float, y: float, under: float = math.inf) -> float | None:
        """Height of the ground a foot finds at (x, y); None over a pit (no ground). Obstacles taller than `under`
        do not count: a foot in the air below their top is at their side (on a face), not on them."""
        for pit in self.scenario.pits:
            if point_in_polygon(x, y, pit):
                return None
        top = 0.0
        for ob in self.scenario.obstacles:
            if ob.height <= under and point_in_polygon(x, y, ob.polygon):
                top = max(top, ob.height)
        return top

    def solid_height_at(self, x: float, y: float) -> float:
        """Height of whatever solid occupies (x, y): 0 for free ground, walls are tall."""
        return self.solid_at(x, y).height

    def solid_at(self, x: float, y: float, seen_from: Pt | None = None) -> SolidHit:
        """The solid occupying (x, y): its height and how far (x, y) lies inside its footprint.

        A wall, or a thin obstacle, is too thin for the distance into it alone to tell a point that went in from
        one that came through: `seen_from` (a leg's hip) counts the depth from the face the line from there
        enters by, on through and past the solid's middle. A foot whose move takes it deeper is stopped
        (sim2d.robot); without the side, a foot that crossed a wall's centre line got shallower, passed behind
        the wall and then stalled its servos on every move back into the room (issue 18, explore seed 2).
        Thin, tall polygon obstacles are measured the same way (issue 18's leftover)."""
        q = self.space.point_query_nearest((x, y), 0.0, SOLID)
        if q is None:
            hit = SolidHit(0.0, 0.0)
        else:
            hit = SolidHit(self.heights.get(q.shape, 0.0), max(0.0, -q.distance), (q.gradient.x, q.gradient.y))
        if seen_from is None:
            return hit
        for w in self.space.segment_query(seen_from, (x, y), 0.0, SOLID):
            if w.alpha <= 0.0:
                continue                                              # the hip is above it: the distance counts
            (px, py), (nx, ny) = w.point, w.normal                    # where the line enters, the face's normal
            depth = (px - x) * nx + (py - y) * ny
            if depth > hit.depth:
                hit = SolidHit(self.heights.get(w.shape, WALL_HEIGHT), depth, (nx, ny))
        return hit

    def in_pit(self, x: float, y: float) -> bool:
        return any(point_in_polygon(x, y, p) for p in self.scenario.pits)

    def incline(self, x: float, y: float) -> tuple[float, float]:
        """Ground inclination (degrees) rising along world +x and +y; the last matching zone wins."""
        ix = iy = 0.0
        for s in self.scenario.slopes:
            if point_in_polygon(x, y, s.polygon):
                ix, iy = s.incline_x, s.incline_y
        return ix, iy

    # --- fields -------------------------------------------------------------
    def lux(self, x: float, y: float) -> float:
        """Illuminance: ambient plus each source's intensity / d^2 unless a wall shades it."""
        total = self.scenario.ambient_lux
        for light in self.scenario.lights:
            lx, ly = light.pos
            d2 = (lx - x) ** 2 + (ly - y) ** 2
            if self.space.segment_query_first((x, y), (lx, ly), 0.0, WALL_ONLY) is None:
                total += light.intensity / max(d2, 0.01)
        return total

    def temperature(self, x: float, y: float) -> float:
        """Ambient plus a Gaussian bump per heat source (no occlusion: heat is a field, not a ray)."""
        t = self.scenario.ambient_temp
        for h in self.scenario.heat:
            d2 = (h.pos[0] - x) ** 2 + (h.pos[1] - y) ** 2
            t += (h.temperature - self.scenario.ambient_temp) * math.exp(-d2 / (h.radius * h.radius))
        return t

    # --- clearance ------------------------------------------------------------
    def clearance(self, outline: list[Pt], min_height: float, reach: float = 1.0) -> float:
        """Smallest distance from a closed outline to a wall/obstacle at least `min_height` tall."""
        xs = [p[0] for p in outline]
        ys = [p[1] for p in outline]
        bb = pymunk.BB(min(xs) - reach, min(ys) - reach, max(xs) + reach, max(ys) + reach)
        near = self.space.bb_query(bb, SOLID)
        best = reach
        if not near:
            return best
        for a, b, h in self.segments:
            if h < min_height:
                continue
            if max(a[0], b[0]) < bb.left or min(a[0], b[0]) > bb.right or max(a[1], b[1]) < bb.bottom or min(a[1], b[1]) > bb.top:
                continue
            for i in range(len(outline)):
                d = seg_seg_distance(outline[i - 1], outline[i], a, b) - (WALL_RADIUS if h == WALL_HEIGHT else 0.0)
                if d < best:
                    best = d
        return max(0.0, best)
