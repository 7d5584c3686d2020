"""The NP3's topological map (seed 3.3.2: "Generieren, modifizieren und adaptieren einer Topologischen Map").

Why two layers: the ultrasonic head (seed 3.2.11: 0..10 m, 1 deg steps, a
full scan within 8 s) gives ranges, which an occupancy grid turns into free
and occupied space; navigation (5.2: 10..30 s per plan) wants few places and
passable connections, which the graph on top of the grid gives:

  - places: in every `place_spacing_m` block of the grid, the free cell
    farthest from any obstacle or unknown cell (a point on the free space's
    medial axis, Voronoi-like), if that clearance is at least the robot's
    radius;
  - edges: between places in neighbouring blocks when the straight line
    between them keeps the robot's clearance all the way (never through a
    wall, never through unknown space).

The map is rebuilt ("modified and adapted") from the grid after each scan;
`coverage()` says how much of a declared room polygon has been seen,
`frontier()` picks the next place to explore (the nearest reachable cluster
of free cells bordering unknown space), `save_png()` draws it all. Pure
Python (no numpy): a 10 m x 10 m room at 10 cm is 10^4 cells.
"""
from __future__ import annotations

import heapq
import math
import statistics
from collections import deque
from dataclasses import dataclass, field
from pathlib import Path
from typing import Iterable, NamedTuple, Sequence

from arachnae_proto.messages import XmitDataUsrc

UNKNOWN, FREE, OCCUPIED = 0, 1, 2

_DISTANCE = next(f for f in XmitDataUsrc.FIELDS if f.name == "distance")
USRC_MAX_RANGE_M = _DISTANCE.conv.to_phys(_DISTANCE.conv.hi)   # seed 3.2.11: 0..255 = 0..10 m, from the spec
USRC_MIN_RANGE_M = 0.3       # seed 5.2: the scanner is used from 30 cm to about 10 m


@dataclass(frozen=True)
class Reading:
    """One ultrasonic reading: robot pose, head angle relative to the body, range (None: no echo)."""

    x: float              # m, world frame
    y: float              # m
    heading_deg: float    # robot heading, counter-clockwise from +x
    head_deg: float       # USRC head angle relative to the body (seed 3.2.11), counter-clockwise
    distance_m: float | None

    @property
    def bearing(self) -> float:
        return math.radians(self.heading_deg + self.head_deg)


@dataclass(frozen=True)
class Place:
    id: int
    x: float
    y: float
    clearance_m: float
    block: tuple[int, int]  # which place_spacing_m block of the grid it stands for


@dataclass(frozen=True)
class Frontier:
    x: float
    y: float
    size: int             # cells in the cluster
    path_m: float         # length of the free path from the robot


class OccupancyGrid:
    """Log-odds occupancy grid over a rectangle; a cell is FREE, OCCUPIED or UNKNOWN."""

    def __init__(self, x0: float, y0: float, width_m: float, height_m: float, resolution_m: float = 0.1) -> None:
        self.x0, self.y0, self.res = x0, y0, resolution_m
        self.nx = max(1, int(math.ceil(width_m / resolution_m)))
        self.ny = max(1, int(math.ceil(height_m / resolution_m)))
        self.logodds = [0.0] * (self.nx * self.ny)
        self.seen = bytearray(self.nx * self.ny)       # ever crossed by a beam: coverage only grows
        self.hit, self.miss, self.limit = 0.9, -0.4, 5.0
        self.barriers: set[tuple[int, int]] = set()      # pit edges and refused slopes (mark_barrier): never cleared

    # -- coordinates ----------------------------------------------------------------
    def cell(self, x: float, y: float) -> tuple[int, int]:
        return int(math.floor((x - self.x0) / self.res)), int(math.floor((y - self.y0) / self.res))

    def centre(self, i: int, j: int) -> tuple[float, float]:
        return self.x0 + (i + 0.5) * self.res, self.y0 + (j + 0.5) * self.res

    def inside(self, i: int, j: int) -> bool:
        return 0 <= i < self.nx and 0 <= j < self.ny

    def state(self, i: int, j: int) -> int:
        if not self.inside(i, j):
            return UNKNOWN
        v = self.logodds[j * self.nx + i]
        return OCCUPIED if v > 0.5 else FREE if v < -0.3 else UNKNOWN

    def state_at(self, x: float, y: float) -> int:
        return self.state(*self.cell(x, y))

    # -- updates --------------------------------------------------------------------
    def _bump(self, i: int, j: int, delta: float) -> None:
        if (i, j) in self.barriers:
            return
        k = j * self.nx + i
        self.logodds[k] = max(-self.limit, min(self.limit, self.logodds[k] + delta))
        self.seen[k] = 1

    def mark_barrier(self, x: float, y: float) -> None:
        """A foot found no ground here (seed 1.2.2) or the ground rises too steeply (3.2.14): the cell is as
        impassable as a wall, for good."""
        i, j = self.cell(x, y)
        if self.inside(i, j):
            k = j * self.nx + i
            self.logodds[k] = self.limit
            self.seen[k] = 1
            self.barriers.add((i, j))

    def occupied_near(self, x: float, y: float, radius_m: float) -> list[tuple[float, float]]:
        """Centres of the occupied cells (walls, blocks, pit edges, refused slopes) within `radius_m` of (x, y):
        what the map remembers round the robot after its short echo memory has let it go."""
        (i0, j0), (i1, j1) = self.cell(x - radius_m, y - radius_m), self.cell(x + radius_m, y + radius_m)
        return [c for j in range(max(0, j0), min(self.ny, j1 + 1)) for i in range(max(0, i0), min(self.nx, i1 + 1))
                if self.state(i, j) == OCCUPIED and math.dist(c := self.centre(i, j), (x, y)) <= radius_m]

    def mark_free(self, x: float, y: float, radius_m: float) -> None:
        """The robot stands here: the cells under its body are free (and seen)."""
        i0, j0 = self.cell(x - radius_m, y - radius_m)
        i1, j1 = self.cell(x + radius_m, y + radius_m)
        for j in range(max(0, j0), min(self.ny, j1 + 1)):
            for i in range(max(0, i0), min(self.nx, i1 + 1)):
                cx, cy = self.centre(i, j)
                if math.hypot(cx - x, cy - y) <= radius_m:
                    self._bump(i, j, self.miss)

    def integrate(self, r: Reading, max_range_m: float = USRC_MAX_RANGE_M) -> None:
        """Free cells along the beam, an occupied cell at the echo (none without an echo).

        Echoes nearer than 30 cm are dropped: the scanner is not used there (seed 5.2).
        """
        if r.distance_m is not None and r.distance_m < USRC_MIN_RANGE_M:
            return
        echo = r.distance_m is not None and r.distance_m < max_range_m
        length = r.distance_m if echo else max_range_m
        # the echo's surface may lie on a cell border: free what the beam crossed in front of it,
        # mark occupied the cell just behind it (a quarter cell either side)
        hit = None
        if echo:
            hit = self.cell(r.x + (length + self.res / 4) * math.cos(r.bearing),
                            r.y + (length + self.res / 4) * math.sin(r.bearing))
        for c in ray_cells(r.x, r.y, r.bearing, length - self.res / 4 if echo else length, self.res, self.x0, self.y0):
            if c != hit and self.inside(*c):
                self._bump(*c, self.miss)
        if hit is not None and self.inside(*hit):
            self._bump(*hit, self.hit)


    def ray_end(self, x: float, y: float, angle: float, max_m: float) -> RayEnd:
        """Where the ray from (x, y) first meets a cell that is not free, within `max_m`: the distance along
        the ray to that cell's centre and whether it is occupied (an echo would come from there) or unknown
        (the map cannot say); (max_m, False) when it runs free all the way."""
        c, s = math.cos(angle), math.sin(angle)
        for i, j in ray_cells(x, y, angle, max_m, self.res, self.x0, self.y0):
            st = self.state(i, j)
            if st != FREE:
                cx, cy = self.centre(i, j)
                return RayEnd((cx - x) * c + (cy - y) * s, st == OCCUPIED)
        return RayEnd(max_m, False)


class RayEnd(NamedTuple):
    """OccupancyGrid.ray_end: how far a ray runs through free cells, and what stops it."""

    dist_m: float
    occupied: bool


def heading_offset(grid: OccupancyGrid, x: float, y: float, bearing: float, d: float, cone_deg: float,
                   rays: int, search_deg: int, tol_m: float, max_width_deg: int) -> float | None:
    """seed 3.3.2: the heading correction (rad) under which the map predicts a sonar echo `d` m away seen at
    `bearing` from (x, y); None when the echo cannot tell (the map does not know the ground there, or it
    fits a band of headings wider than `max_width_deg`, as a wall seen square on does).

    The echo is the nearest surface within the cone (`rays` rays across `cone_deg`, as the transducer
    sees it), so the prediction for a heading offset is the nearest occupied cell over the same rays turned
    by that offset, searched within +-`search_deg` in whole degrees; the offsets that predict `d` within
    `tol_m` must form a band narrower than `max_width_deg` that does not touch the search's ends.
    """
    offs = [round(-cone_deg / 2 + cone_deg * k / (rays - 1)) for k in range(rays)] if rays > 1 else [0]
    reach = d + 2 * tol_m
    ends = {a: grid.ray_end(x, y, bearing + math.radians(a), reach)
            for a in range(-search_deg + min(offs), search_deg + max(offs) + 1)}
    fits: list[int] = []
    known = 0
    for delta in range(-search_deg, search_deg + 1):
        near = min((ends[delta + o] for o in offs), key=lambda e: (e.dist_m, not e.occupied))
        if not near.occupied and near.dist_m < reach:
            continue                                   # unknown ground before the echo: no prediction
        known += 1
        if near.occupied and abs(near.dist_m - grid.res / 4 - d) <= tol_m:
            fits.append(delta)
    if not fits or known < search_deg or max(fits) - min(fits) > max_width_deg \
            or -search_deg in fits or search_deg in fits:
        return None
    return math.radians(sum(fits) / len(fits))


@dataclass
class HeadingVotes:
    """seed 3.3.2: the dead-reckoned heading drifts (the feet slip, a reflex or a bump turns the body; the
    gait's own pauses are in the dead reckoning, np3.GaitReckoning), and a map drawn with a drifting heading is drawn rotated: a wall's end is
    not where the map has it (light_behind_wall seeds 9, 10, issue 17). So echoes of mapped surfaces vote
    for the heading offset that makes them fit the map (heading_offset), and every `count` votes the
    heading is corrected by `gain` x their median, at most `max_step` rad at a time."""

    count: int
    gain: float
    max_step: float
    votes: list[float] = field(default_factory=list)

    def add(self, offset: float) -> float:
        """One echo's vote; the correction (rad) to apply now, 0.0 until `count` votes are in."""
        self.votes.append(offset)
        if len(self.votes) < self.count:
            return 0.0
        mid = statistics.median(self.votes)
        self.votes.clear()
        return max(-self.max_step, min(self.max_step, self.gain * mid))


def _pit_distance(g: OccupancyGrid, pits: Sequence[tuple[float, float]],
                 reach_m: float) -> dict[tuple[int, int], float]:
    """The distance (m) from each cell within `reach_m` of some pit point to the nearest one."""
    out: dict[tuple[int, int], float] = {}
    n = int(math.ceil(reach_m / g.res))
    for px, py in pits:
        pi, pj = g.cell(px, py)
        for j in range(pj - n, pj + n + 1):
            for i in range(pi - n, pi + n + 1):
                d = math.dist(g.centre(i, j), (px, py))
                if d <= reach_m and d < out.get((i, j), math.inf):
                    out[(i, j)] = d
    return out


def ray_cells(x: float, y: float, angle: float, length: float, res: float, x0: float = 0.0,
              y0: float = 0.0) -> Iterable[tuple[int, int]]:
    """Every grid cell the ray from (x, y) crosses within `length` (Amanatides-Woo traversal)."""
    dx, dy = math.cos(angle), math.sin(angle)
    gx, gy = (x - x0) / res, (y - y0) / res
    i, j = int(math.floor(gx)), int(math.floor(gy))
    step_i, step_j = (1 if dx > 0 else -1), (1 if dy > 0 else -1)
    t_max_i = ((i + (dx > 0)) - gx) * res / dx if dx else math.inf
    t_max_j = ((j + (dy > 0)) - gy) * res / dy if dy else math.inf
    t_delta_i = res / abs(dx) if dx else math.inf
    t_delta_j = res / abs(dy) if dy else math.inf
    while True:
        yield i, j
        if min(t_max_i, t_max_j) > length:
            return
        if t_max_i < t_max_j:
            i += step_i
            t_max_i += t_delta_i
        else:
            j += step_j
            t_max_j += t_delta_j


def line_cells(a: tuple[int, int], b: tuple[int, int]) -> Iterable[tuple[int, int]]:
    """Bresenham: the grid cells on the segment a-b, a first, b last."""
    (x, y), (x1, y1) = a, b
    dx, dy = abs(x1 - x), -abs(y1 - y)
    sx, sy = (1 if x1 > x else -1), (1 if y1 > y else -1)
    err = dx + dy
    while True:
        yield x, y
        if (x, y) == (x1, y1):
            return
        e2 = 2 * err
        if e2 >= dy:
            err += dy
            x += sx
        if e2 <= dx:
            err += dx
            y += sy


def point_in_polygon(x: float, y: float, poly: Sequence[tuple[float, float]]) -> bool:
    inside = False
    n = len(poly)
    for k in range(n):
        (xa, ya), (xb, yb) = poly[k], poly[(k + 1) % n]
        if (ya > y) != (yb > y) and x < xa + (y - ya) * (xb - xa) / (yb - ya):
            inside = not inside
    return inside


_N8 = ((1, 0), (-1, 0), (0, 1), (0, -1), (1, 1), (1, -1), (-1, 1), (-1, -1))


class TopoMap:
    """Grid + places + edges + the robot's path, rebuilt from the grid after every scan."""

    def __init__(self, grid: OccupancyGrid, robot_radius_m: float = 0.25, place_spacing_m: float = 1.0,
                 room: Sequence[tuple[float, float]] | None = None) -> None:
        self.grid = grid
        self.robot_radius_m = robot_radius_m
        self.place_spacing_m = place_spacing_m
        self.room = list(room) if room else None
        self.path: list[tuple[float, float]] = []
        self.plan: list[tuple[float, float]] = []       # the route the robot follows now (drawn on the picture)
        self.places: list[Place] = []
        self.edges: set[tuple[int, int]] = set()
        self.clearance: list[float] = []

    # -- building -------------------------------------------------------------------
    def add_scan(self, readings: Iterable[Reading]) -> None:
        """Integrate one scan and adapt the graph to it."""
        self.add(readings)
        self.rebuild()

    def add(self, readings: Iterable[Reading]) -> None:
        """Integrate readings without rebuilding the graph (single echoes arrive one by one)."""
        for r in readings:
            self.visit(r.x, r.y)
            self.grid.integrate(r)

    def visit(self, x: float, y: float) -> None:
        if not self.path or self.path[-1] != (x, y):
            self.path.append((x, y))

    def rebuild(self) -> None:
        self.clearance = self._clearance()
        self.places = self._places()
        self.edges = self._edges()

    def _clearance(self) -> list[float]:
        """Distance in m from each free cell to the nearest non-free cell (multi-source BFS, 8-connected)."""
        g = self.grid
        dist = [math.inf] * (g.nx * g.ny)
        queue: deque[tuple[int, int]] = deque()
        for j in range(g.ny):
            for i in range(g.nx):
                if g.state(i, j) != FREE:
                    dist[j * g.nx + i] = 0.0
                    queue.append((i, j))
        while queue:
            i, j = queue.popleft()
            d = dist[j * g.nx + i]
            for di, dj in _N8:
                a, b = i + di, j + dj
                if g.inside(a, b) and dist[b * g.nx + a] > d + 1:
                    dist[b * g.nx + a] = d + 1
                    queue.append((a, b))
        for j in range(g.ny):                        # beyond the grid's border is unknown too
            for i in range(g.nx):
                dist[j * g.nx + i] = min(dist[j * g.nx + i], i + 1, j + 1, g.nx - i, g.ny - j)
        return [d * g.res for d in dist]

    def _places(self) -> list[Place]:
        g, block = self.grid, max(1, int(round(self.place_spacing_m / self.grid.res)))
        places: list[Place] = []
        for bj in range(0, g.ny, block):
            for bi in range(0, g.nx, block):
                best, best_c = None, self.robot_radius_m
                for j in range(bj, min(bj + block, g.ny)):
                    for i in range(bi, min(bi + block, g.nx)):
                        c = self.clearance[j * g.nx + i]
                        if c >= best_c and (best is None or c > best_c):
                            best, best_c = (i, j), c
                if best is not None:
                    x, y = g.centre(*best)
                    places.append(Place(len(places), x, y, best_c, (bi // block, bj // block)))
        return places

    def passable(self, a: tuple[float, float], b: tuple[float, float]) -> bool:
        """The robot's disc fits along the straight segment a-b (free cells with clearance >= radius)."""
        g = self.grid
        for i, j in line_cells(g.cell(*a), g.cell(*b)):
            if not g.inside(i, j) or self.clearance[j * g.nx + i] < self.robot_radius_m:
                return False
        return True

    def _edges(self) -> set[tuple[int, int]]:
        """Places of 8-neighbouring blocks, where the robot fits along the straight line between them."""
        edges = set()
        for a in self.places:
            for b in self.places:
                near = max(abs(a.block[0] - b.block[0]), abs(a.block[1] - b.block[1])) == 1
                if a.id < b.id and near and self.passable((a.x, a.y), (b.x, b.y)):
                    edges.add((a.id, b.id))
        return edges

    # -- questions ------------------------------------------------------------------
    def neighbours(self, place_id: int) -> set[int]:
        return {b if a == place_id else a for a, b in self.edges if place_id in (a, b)}

    def component(self, place_id: int) -> set[int]:
        seen, todo = {place_id}, [place_id]
        while todo:
            for n in self.neighbours(todo.pop()):
                if n not in seen:
                    seen.add(n)
                    todo.append(n)
        return seen

    def route(self, start: tuple[float, float], goal: tuple[float, float]) -> list[tuple[float, float]] | None:
        """seed 3.3.2: the shortest way over the places graph (A*) from `start` to `goal`, as waypoints ending
        at `goal`; None when the map joins them by no passable edges.

        Start and goal join the graph at the nearest places they reach in a straight passable line, else at
        their nearest place (the robot may stand close to a wall, a frontier lies next to unknown space,
        where the clearance is small by definition). Call rebuild() after new readings: the route is only
        as good as the graph.
        """
        if not self.places:
            return None

        def entry(p: tuple[float, float]) -> list[Place]:
            near = sorted(self.places, key=lambda q: math.dist(p, (q.x, q.y)))[:6]
            return [q for q in near if self.passable(p, (q.x, q.y))] or near[:1]

        starts, goals = entry(start), {q.id: q for q in entry(goal)}
        if not starts or not goals:
            return None
        by_id = {q.id: q for q in self.places}
        adj: dict[int, list[int]] = {q.id: [] for q in self.places}
        for a, b in self.edges:
            adj[a].append(b)
            adj[b].append(a)

        def h(q: Place) -> float:
            return math.dist((q.x, q.y), goal)

        best = {q.id: math.dist(start, (q.x, q.y)) for q in starts}
        came: dict[int, int | None] = {q.id: None for q in starts}
        todo = [(best[q.id] + h(q), q.id) for q in starts]
        heapq.heapify(todo)
        while todo:
            _f, cur = heapq.heappop(todo)
            if cur in goals:
                ids = [cur]
                while came[ids[-1]] is not None:
                    ids.append(came[ids[-1]])  # type: ignore[arg-type]
                return [(by_id[i].x, by_id[i].y) for i in reversed(ids)] + [goal]
            for n in adj[cur]:
                d = best[cur] + math.dist((by_id[cur].x, by_id[cur].y), (by_id[n].x, by_id[n].y))
                if d < best.get(n, math.inf):
                    best[n], came[n] = d, cur
                    heapq.heappush(todo, (d + h(by_id[n]), n))
        return None

    def route_out(self, start: tuple[float, float], centre: tuple[float, float], radius_m: float,
                  pits: Sequence[tuple[float, float]], wary_m: float, wary_cost: float,
                  start_m: float = 0.4) -> list[tuple[float, float]] | None:
        """seed 3.3.2: a way out of a ring of pits: the cheapest path over the grid from `start` to a cell more
        than `radius_m` from `centre`, as waypoints (the straight stretches the robot's disc fits along, the
        goal last); None when the map leaves none (call rebuild() first, for the clearance).

        Over grid cells, not the places graph: the goal is a region (anywhere beyond the radius), not a point,
        and the cost is per cell (the wariness below); the graph's places stand `place_spacing_m` apart (1 m
        for the NP3), and a 0.4 m long, 0.8 m wide gap gets no place of its own. A cell is
        passable where the robot's disc fits (clearance >= its radius), or within `start_m` of the start (it
        backed off from a pit: its own ground is free). CHOICE: a cell within `wary_m` of a pit cell found
        (`pits`) costs up to `wary_cost` times its length more, the most next to it: a pit's edge runs on
        past what one foot found, so the way out is tried first where no pit has been met, not along the
        ends of the stretches already mapped (that slid round the ring 0.3 m per pit report).
        """
        g, r = self.grid, self.robot_radius_m
        s0 = g.cell(*start)
        if not g.inside(*s0) or not self.clearance:
            return None
        near = _pit_distance(g, pits, wary_m)
        best = {s0: 0.0}
        came: dict[tuple[int, int], tuple[int, int]] = {}
        todo = [(0.0, s0)]
        goal: tuple[int, int] | None = None
        while todo:
            d, c = heapq.heappop(todo)
            if d > best.get(c, math.inf):
                continue
            if math.dist(g.centre(*c), centre) > radius_m:
                goal = c
                break
            for di, dj in _N8:
                n = (c[0] + di, c[1] + dj)
                if not g.inside(*n):
                    continue
                k = n[1] * g.nx + n[0]
                if self.clearance[k] < r and not (g.state(*n) == FREE and math.dist(g.centre(*n), start) <= start_m):
                    continue
                wary = 1.0 + wary_cost * max(0.0, 1.0 - near.get(n, math.inf) / wary_m)
                nd = d + g.res * math.hypot(di, dj) * wary
                if nd < best.get(n, math.inf):
                    best[n], came[n] = nd, c
                    heapq.heappush(todo, (nd, n))
        if goal is None:
            return None
        cells = [goal]
        while cells[-1] != s0:
            cells.append(came[cells[-1]])
        cells.reverse()
        return self._straightened(start, [g.centre(*c) for c in cells])

    def _straightened(self, start: tuple[float, float], pts: list[tuple[float, float]]) -> list[tuple[float, float]]:
        """A grid path as few waypoints: from each waypoint on, the farthest point of the path the robot's disc
        reaches in a straight passable line (the first step always, whatever its clearance)."""
        out: list[tuple[float, float]] = []
        at, k = start, 0
        while k < len(pts) - 1:
            nxt = k + 1
            for m in range(len(pts) - 1, k + 1, -1):
                if self.passable(at, pts[m]):
                    nxt = m
                    break
            at, k = pts[nxt], nxt
            out.append(at)
        return out or pts[-1:]

    @staticmethod
    def length(start: tuple[float, float], route: Sequence[tuple[float, float]]) -> float:
        """The length (m) of a route's waypoints walked from `start`."""
        return sum(math.dist(a, b) for a, b in zip([start, *route], route))

    def coverage(self) -> float:
        """Share of the room polygon's cells that some beam has crossed or hit (0..1)."""
        if not self.room:
            raise ValueError("no room polygon declared")
        g = self.grid
        total = seen = 0
        for j in range(g.ny):
            for i in range(g.nx):
                if point_in_polygon(*g.centre(i, j), self.room):
                    total += 1
                    seen += g.seen[j * g.nx + i]
        return seen / total if total else 0.0

    def _open_unknown(self, i: int, j: int) -> bool:
        """An unknown cell with no occupied neighbour (one next to an occupied cell is most likely a wall cell
        a grazing beam missed)."""
        g = self.grid
        return g.inside(i, j) and g.state(i, j) == UNKNOWN and all(
            g.state(i + di, j + dj) != OCCUPIED for di, dj in _N8)

    def is_frontier(self, c: tuple[int, int]) -> bool:
        """A free cell bordering open unknown space."""
        return self.grid.state(*c) == FREE and any(self._open_unknown(c[0] + di, c[1] + dj) for di, dj in _N8)

    def frontier_near(self, x: float, y: float, radius_m: float) -> bool:
        """Some frontier cell lies within `radius_m` of (x, y): a frontier chosen there is not yet explored."""
        g = self.grid
        (i0, j0), (i1, j1) = g.cell(x - radius_m, y - radius_m), g.cell(x + radius_m, y + radius_m)
        return any(self.is_frontier((i, j)) and math.dist(g.centre(i, j), (x, y)) <= radius_m
                   for j in range(j0, j1 + 1) for i in range(i0, i1 + 1))

    def frontier(self, x: float, y: float, min_size: int = 5, min_path_m: float = 0.0,
                 size_weight: float = 0.0, exclude: Sequence[tuple[float, float]] = (),
                 exclude_m: float = 0.0) -> Frontier | None:
        """The nearest (by free path) cluster of free cells bordering open unknown space; None when explored.

        Clusters smaller than `min_size` cells are gaps between diverging beams,
        not frontiers; cells nearer than `min_path_m` are where the robot already is.
        With `size_weight` a cluster's path counts that many metres less per cell of its edge (a wide opening
        onto unknown space is worth a longer walk than a sliver, the usual gain-minus-cost frontier choice).
        Cells within `exclude_m` of an `exclude` point do not count: frontiers the robot gave up on (no
        revisits).
        """
        g = self.grid
        start = g.cell(x, y)
        if not g.inside(*start):
            return None
        dist = {start: 0.0}
        queue = deque([start])
        while queue:                                 # reachable free cells, path length in m
            i, j = queue.popleft()
            for di, dj in _N8:
                n = (i + di, j + dj)
                if n not in dist and g.state(*n) == FREE:
                    dist[n] = dist[(i, j)] + g.res * math.hypot(di, dj)
                    queue.append(n)

        def excluded(c: tuple[int, int]) -> bool:
            return any(math.dist(g.centre(*c), p) < exclude_m for p in exclude)

        cells = {c for c in dist if dist[c] >= min_path_m and self.is_frontier(c) and not excluded(c)}
        best: Frontier | None = None
        while cells:
            seed = min(cells)
            cluster, todo = [seed], [seed]
            cells.discard(seed)
            while todo:
                i, j = todo.pop()
                for di, dj in _N8:
                    n = (i + di, j + dj)
                    if n in cells:
                        cells.discard(n)
                        cluster.append(n)
                        todo.append(n)
            if len(cluster) < min_size:
                continue
            target = min(cluster, key=lambda c: (dist[c], c))
            cand = Frontier(*g.centre(*target), size=len(cluster), path_m=dist[target])
            if best is None or (cand.path_m - size_weight * cand.size, -cand.size) < \
                    (best.path_m - size_weight * best.size, -best.size):
                best = cand
        return best

    # -- picture --------------------------------------------------------------------
    def save_png(self, path: str | Path, px_per_cell: int = 4,
                 given_up: Sequence[tuple[float, float]] = (),
                 plan: Sequence[tuple[float, float]] | None = None,
                 routes: Sequence[Sequence[tuple[float, float]]] = (),
                 pits: Iterable[tuple[float, float]] = ()) -> Path:
        """Grid (unknown grey, free white, occupied black, pit cells dark red), room outline, edges, places,
        robot path, earlier `routes` (thin green, each from where it was planned), the plan (green, to a square
        at its goal; `plan` instead of self.plan when the caller knows better) and frontiers given up
        (FrontierTarget, purple crosses)."""
        from PIL import Image, ImageDraw

        g, s = self.grid, px_per_cell
        img = Image.new("RGB", (g.nx * s, g.ny * s), (160, 160, 160))
        draw = ImageDraw.Draw(img)
        colour = {UNKNOWN: (160, 160, 160), FREE: (255, 255, 255), OCCUPIED: (0, 0, 0)}
        for j in range(g.ny):
            for i in range(g.nx):
                st = g.state(i, j)
                if st != UNKNOWN:
                    top = (g.ny - 1 - j) * s
                    draw.rectangle((i * s, top, i * s + s - 1, top + s - 1), fill=colour[st])

        def px(x: float, y: float) -> tuple[float, float]:
            return (x - g.x0) / g.res * s, (g.ny - (y - g.y0) / g.res) * s

        for i, j in {g.cell(*p) for p in pits}:
            top = (g.ny - 1 - j) * s
            draw.rectangle((i * s, top, i * s + s - 1, top + s - 1), fill=(150, 0, 0))

        if self.room:
            draw.polygon([px(*p) for p in self.room], outline=(0, 160, 0))
        by_id = {p.id: p for p in self.places}
        for a, b in sorted(self.edges):
            draw.line([px(by_id[a].x, by_id[a].y), px(by_id[b].x, by_id[b].y)], fill=(40, 90, 230), width=2)
        for p in self.places:
            (cx, cy), r = px(p.x, p.y), max(3, s)
            draw.ellipse((cx - r, cy - r, cx + r, cy + r), fill=(220, 30, 30))
        if len(self.path) > 1:
            draw.line([px(*p) for p in self.path], fill=(230, 140, 0), width=2)
        for r in routes:
            if len(r) > 1:
                draw.line([px(*p) for p in r], fill=(120, 210, 140), width=1)
        plan = self.plan if plan is None else list(plan)
        if plan:                                       # the route being followed, from the robot on
            pts = [px(*p) for p in ([self.path[-1]] if self.path else []) + plan]
            draw.line(pts, fill=(0, 170, 60), width=3)
            (gx, gy), r = pts[-1], max(5, 2 * s)
            draw.rectangle((gx - r, gy - r, gx + r, gy + r), outline=(0, 170, 60), width=2)
        for p in given_up:
            (cx, cy), r = px(*p), max(4, s)
            draw.line((cx - r, cy - r, cx + r, cy + r), fill=(150, 40, 170), width=2)
            draw.line((cx - r, cy + r, cx + r, cy - r), fill=(150, 40, 170), width=2)
        out = Path(path)
        img.save(out, format="PNG")
        return out


class Stuck(NamedTuple):
    """FrontierTarget: a route's next waypoint the robot could not get past, and where the robot was then."""
    waypoint: tuple[float, float]
    at: tuple[float, float]


_TRIES = 12      # FrontierTarget.route: at most this many frontiers looked at per replan (each one a map search)


@dataclass
class FrontierTarget:
    """seed 3.3.2: the frontier the robot's routes lead to, kept from one replan to the next.

    Choosing the nearest frontier afresh at every replan swapped between frontiers as the map grew and
    reached none (light_behind_wall, issue 17). So the target is kept, and routed to again on the rebuilt
    map at every replan (the map changed, so may the route), until it is reached (within `exclude_m`: a
    frontier by a wall may lie where the body cannot stand, light_behind_wall seed 4 spent 40 s 0.45 m from
    one), explored (no frontier cell left within `exclude_m`), refuted (no route leads there) or not
    approached (its route not `progress_m` shorter for `patience_s`). Then it is given up, frontier cells near it no longer count (no revisits)
    and the next frontier is chosen. A target not approached leaves its route's next waypoint as one the
    robot could not get past: a frontier whose route leads through it (a waypoint within `exclude_m`) is
    given up at once, not after another `patience_s` (light_behind_wall seed 5 on an earlier branch: 90 s on
    frontiers behind the same unreachable waypoint), while the robot is within `stuck_near_m` of where it was stuck;
    those do not count among the three choices a replan has (the kept target, a new one, start over).
    When every frontier left has been given up, they count again and the waypoints are forgotten (the map
    has grown since: start over rather than stop).
    """

    exclude_m: float
    progress_m: float
    patience_s: float
    target: tuple[float, float] | None = None
    left_m: float = math.inf                  # the shortest route to the target so far
    closer_at: float = 0.0                    # when that last shortened
    given_up: list[tuple[float, float]] = field(default_factory=list)
    stuck: list[Stuck] = field(default_factory=list)   # waypoints of routes not approached, while still near
    stuck_near_m: float = 1.0     # CHOICE: ... where it was stuck (further off, another way may lead past it)

    def route(self, topo: TopoMap, x: float, y: float, now: float, reached_m: float, min_size: int = 5,
              min_path_m: float = 0.0, size_weight: float = 0.0) -> list[tuple[float, float]]:
        """The route from (x, y) to the target over `topo` (rebuilt by the caller), waypoints nearer than
        `reached_m` dropped; [] when no frontier is left to explore. The frontier arguments: TopoMap.frontier."""
        self.stuck = [s for s in self.stuck if math.dist(s.at, (x, y)) <= self.stuck_near_m]
        choices = 0            # the kept target, else (given up) a new one, else start over; frontiers given up
        for _try in range(_TRIES):     # behind a stuck waypoint do not count (the map shrinks by one each try)
            if choices == 3:
                break
            if self.target is None:
                f = topo.frontier(x, y, min_size=min_size, min_path_m=min_path_m, size_weight=size_weight,
                                  exclude=self.given_up, exclude_m=self.exclude_m)
                if f is None and self.given_up:       # all explored or given up: the map has grown since,
                    self.given_up.clear()             # so start over rather than stop
                    self.stuck.clear()
                    choices += 1
                    continue
                if f is None:
                    return []
                self.target, self.left_m, self.closer_at = (f.x, f.y), math.inf, now
            route = topo.route((x, y), self.target) or []
            while route and math.dist(route[0], (x, y)) < reached_m:
                route.pop(0)
            left = topo.length((x, y), route)
            if left < self.left_m - self.progress_m:
                self.left_m, self.closer_at = left, now
            patient, behind = now - self.closer_at <= self.patience_s, self._through_stuck(route)
            if route and math.dist(self.target, (x, y)) > self.exclude_m and patient and not behind \
                    and topo.frontier_near(*self.target, self.exclude_m):
                return route
            if route and not patient:
                self.stuck.append(Stuck(route[0], (x, y)))    # the waypoint it could not get past
            self.given_up.append(self.target)
            self.target = None
            choices += not behind
        return []

    def _through_stuck(self, route: Sequence[tuple[float, float]]) -> bool:
        """Whether a route leads through a waypoint the robot could not get past (within `exclude_m`)."""
        return any(math.dist(w, s.waypoint) < self.exclude_m for w in route for s in self.stuck)


def full_scan(x: float, y: float, heading_deg: float, ranges: Sequence[float | None],
              step_deg: float = 1.0) -> list[Reading]:
    """Readings of one USRC sweep (seed 3.2.11: 360 deg at 1 deg) from `ranges[k]` at head angle k*step."""
    return [Reading(x, y, heading_deg, k * step_deg, d) for k, d in enumerate(ranges)]


__all__ = ["RayEnd", "heading_offset", "HeadingVotes", "Reading", "Place", "Frontier", "FrontierTarget", "OccupancyGrid", "TopoMap", "full_scan", "line_cells", "ray_cells",
           "point_in_polygon", "Stuck", "UNKNOWN", "FREE", "OCCUPIED", "USRC_MAX_RANGE_M", "USRC_MIN_RANGE_M"]
