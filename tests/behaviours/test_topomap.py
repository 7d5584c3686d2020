"""NP3 topological map (seed 3.3.2) from synthetic ultrasonic scans of known rooms."""
from __future__ import annotations

import math
import statistics

import pytest
from PIL import Image

from behaviours.topomap import (FREE, OCCUPIED, UNKNOWN, FrontierTarget, HeadingVotes, OccupancyGrid, Reading, Stuck,
                               TopoMap, full_scan, heading_offset)

Segment = tuple[tuple[float, float], tuple[float, float]]


def box(x0: float, y0: float, x1: float, y1: float) -> list[Segment]:
    return [((x0, y0), (x1, y0)), ((x1, y0), (x1, y1)), ((x1, y1), (x0, y1)), ((x0, y1), (x0, y0))]


def cast(walls: list[Segment], x: float, y: float, angle: float, max_range: float = 10.0) -> float | None:
    """Distance to the first wall along the ray (None beyond the USRC's 10 m, seed 3.2.11)."""
    dx, dy = math.cos(angle), math.sin(angle)
    best = None
    for (ax, ay), (bx, by) in walls:
        ex, ey = bx - ax, by - ay
        den = dx * ey - dy * ex
        if abs(den) < 1e-12:
            continue
        t = ((ax - x) * ey - (ay - y) * ex) / den        # along the ray
        u = ((ax - x) * dy - (ay - y) * dx) / den        # along the wall
        if t > 0 and 0 <= u <= 1 and (best is None or t < best):
            best = t
    return best if best is not None and best < max_range else None


def scan(walls: list[Segment], x: float, y: float, heading_deg: float = 0.0) -> list[Reading]:
    ranges = [cast(walls, x, y, math.radians(heading_deg + k)) for k in range(360)]
    return full_scan(x, y, heading_deg, ranges)


ROOM = box(0, 0, 6, 6)
ROOM_POLY = [(0, 0), (6, 0), (6, 6), (0, 6)]
POSES = [(1.5, 1.5, 0), (4.5, 1.5, 90), (3.0, 3.0, 45), (1.5, 4.5, 180), (4.5, 4.5, 270)]


def new_map(room=None, width=7.0, height=7.0) -> TopoMap:
    return TopoMap(OccupancyGrid(-0.5, -0.5, width, height, 0.1), robot_radius_m=0.25, place_spacing_m=1.0, room=room)


@pytest.fixture(scope="module")
def square_room() -> TopoMap:
    m = new_map(ROOM_POLY)
    for pose in POSES:
        m.add_scan(scan(ROOM, *pose))
    return m


def distance_to_walls(walls: list[Segment], x: float, y: float) -> float:
    def seg(p, a, b):
        (px, py), (ax, ay), (bx, by) = p, a, b
        t = max(0.0, min(1.0, ((px - ax) * (bx - ax) + (py - ay) * (by - ay)) / ((bx - ax) ** 2 + (by - ay) ** 2)))
        return math.hypot(px - ax - t * (bx - ax), py - ay - t * (by - ay))
    return min(seg((x, y), a, b) for a, b in walls)


def test_walls_appear_in_the_grid_where_they_are(square_room):
    g = square_room.grid
    occupied = [(i, j) for j in range(g.ny) for i in range(g.nx) if g.state(i, j) == OCCUPIED]
    assert occupied
    # every occupied cell lies on a wall (within one cell diagonal)
    assert max(distance_to_walls(ROOM, *g.centre(i, j)) for i, j in occupied) <= 0.15
    # and the walls are (almost) continuously marked: sample every 10 cm along them
    samples = [(x / 10, y) for x in range(1, 60) for y in (0.0, 6.0)]
    samples += [(x, y / 10) for y in range(1, 60) for x in (0.0, 6.0)]
    marked = sum(any(g.state(*g.cell(sx + dx, sy + dy)) == OCCUPIED for dx in (-0.05, 0.05) for dy in (-0.05, 0.05))
                 for sx, sy in samples)
    assert marked / len(samples) > 0.95
    # the inside is free, the outside unknown
    assert g.state_at(3.05, 3.05) == FREE and g.state_at(0.55, 5.45) == FREE
    assert g.state_at(-0.35, 3.0) == UNKNOWN and g.state_at(6.35, 6.35) == UNKNOWN


def test_places_lie_in_free_space_and_one_room_is_one_connected_graph(square_room):
    places = square_room.places
    assert len(places) >= 16                         # about one per square metre of a 6 m x 6 m room
    for p in places:
        assert 0 < p.x < 6 and 0 < p.y < 6
        assert distance_to_walls(ROOM, p.x, p.y) >= 0.25 - 0.1   # robot radius, within a cell
    assert square_room.component(places[0].id) == {p.id for p in places}


def two_rooms(door: bool) -> tuple[TopoMap, list[Segment]]:
    walls = box(0, 0, 8, 4)
    walls += [((4, 0), (4, 1.5)), ((4, 2.5), (4, 4))] if door else [((4, 0), (4, 4))]
    m = new_map(width=9.0, height=5.0)
    for pose in [(2, 2, 0), (1, 1, 0), (1, 3, 0), (6, 2, 0), (7, 1, 0), (7, 3, 0), (3, 2, 0), (5, 2, 0)]:
        m.add_scan(scan(walls, *pose))
    return m, walls


def test_graph_never_crosses_a_wall_and_connects_through_a_door():
    closed, _ = two_rooms(door=False)
    left = {p.id for p in closed.places if p.x < 4}
    right = {p.id for p in closed.places if p.x > 4}
    assert left and right and not left & right
    by_id = {p.id: p for p in closed.places}
    for a, b in closed.edges:
        assert (by_id[a].x < 4) == (by_id[b].x < 4), "edge through the wall"
    some_left = min(left)
    assert closed.component(some_left) == left       # the left room is one connected graph
    assert closed.component(min(right)) == right

    opened, _ = two_rooms(door=True)
    ids = {p.id for p in opened.places}
    assert opened.component(min(ids)) == ids         # a 1 m door lets the robot (r = 0.25 m) through


def test_coverage_grows_monotonically_with_more_scans():
    # two rooms without a door: scans in the left room cannot see the right one
    walls = box(0, 0, 8, 4) + [((4, 0), (4, 4))]
    m = new_map(room=[(0, 0), (8, 0), (8, 4), (0, 4)], width=9.0, height=5.0)
    shares = [m.coverage()]
    for pose in [(2, 2, 0), (1, 1, 0), (6, 2, 0), (7, 3, 0)]:
        m.add_scan(scan(walls, *pose))
        shares.append(m.coverage())
    assert shares[0] == 0.0
    assert all(b >= a for a, b in zip(shares, shares[1:]))
    assert 0.4 < shares[1] < 0.6                     # the left half
    assert shares[3] > shares[2] and shares[-1] > 0.95


def test_frontier_points_into_unknown_space_and_vanishes_when_explored():
    # a corridor room seen only from its left end: the unexplored right part is the frontier
    walls = box(0, 0, 12, 2)
    m = TopoMap(OccupancyGrid(-0.5, -0.5, 13.0, 3.0, 0.1))
    m.add_scan(scan(walls, 1.0, 1.0))
    f = m.frontier(1.0, 1.0)
    assert f is not None and f.x > 5.0 and f.size >= 5     # towards the unseen right end, not at the walls
    assert f.path_m == pytest.approx(f.x - 1.0, abs=1.0)
    for x in (5.0, 9.0, 11.0):
        m.add_scan(scan(walls, x, 1.0))
    assert m.frontier(11.0, 1.0) is None


def test_frontier_size_weight_prefers_a_wide_opening_to_a_near_sliver():
    # a free strip between two walls (pits), open at its near left end (a sliver) and widening into unknown
    # space at its far right end: the nearest frontier is the sliver; weighted by size, the wide opening
    g = OccupancyGrid(-1.0, -1.0, 8.0, 4.0, 0.1)
    m = TopoMap(g)
    for k in range(81):
        g.mark_free(0.5 + 0.05 * k, 1.0, 0.3)
    g.mark_free(4.5, 1.0, 0.8)
    for k in range(69):
        g.mark_barrier(0.2 + 0.05 * k, 0.6)
        g.mark_barrier(0.2 + 0.05 * k, 1.4)
    near = m.frontier(1.0, 1.0, min_size=3)
    wide = m.frontier(1.0, 1.0, min_size=3, size_weight=0.1)
    assert near is not None and near.x < 0.5
    assert wide is not None and wide.x > 3.0 and wide.size > 5 * near.size and wide.path_m > near.path_m


def test_png_has_the_grid_size_and_shows_walls_places_and_unknown(tmp_path, square_room):
    out = square_room.save_png(tmp_path / "map.png", px_per_cell=4)
    img = Image.open(out)
    g = square_room.grid
    assert img.format == "PNG" and img.size == (g.nx * 4, g.ny * 4)
    rgb = img.convert("RGB")

    def pixel(x: float, y: float) -> tuple[int, int, int]:
        i, j = g.cell(x, y)
        return rgb.getpixel((i * 4 + 2, (g.ny - 1 - j) * 4 + 2))

    assert pixel(-0.35, -0.35) == (160, 160, 160)            # unknown outside the room
    assert pixel(-0.35, 3.0) == (160, 160, 160)
    colours = {rgb.getpixel((u, v)) for u in range(img.size[0]) for v in range(img.size[1])}
    assert (0, 0, 0) in colours and (220, 30, 30) in colours and (255, 255, 255) in colours


def test_a_route_goes_round_through_the_door_and_never_through_the_wall(tmp_path):
    closed, _ = two_rooms(door=False)
    start, goal = (2.0, 3.3), (6.0, 3.3)                         # the straight line runs into the wall
    assert closed.route(start, goal) is None                      # no door: no way
    opened, walls = two_rooms(door=True)
    route = opened.route(start, goal)
    assert route is not None and route[-1] == goal
    legs = list(zip([start] + route, route))
    for a, b in legs[1:-1]:                                        # between places: the robot fits all the way
        assert opened.passable(a, b)
    crossing = [(a, b) for a, b in legs if (a[0] < 4) != (b[0] < 4)]
    assert crossing and all(1.5 < (a[1] + b[1]) / 2 < 2.5 for a, b in crossing)    # through the door (y 1.5..2.5)
    opened.plan = route
    out = opened.save_png(tmp_path / "plan.png", given_up=[(1.0, 1.0)])
    img = Image.open(out).convert("RGB")
    assert any(img.getpixel((x, y)) == (0, 170, 60) for x in range(img.width) for y in range(0, img.height, 2))
    i, j = opened.grid.cell(1.0, 1.0)                              # a frontier given up: a cross there
    assert img.getpixel((i * 4 + 2, (opened.grid.ny - 1 - j) * 4 + 2)) == (150, 40, 170)
    none = Image.open(opened.save_png(tmp_path / "none.png", plan=[])).convert("RGB")   # a plan not followed
    assert all(none.getpixel((x, y)) != (0, 170, 60) for x in range(none.width) for y in range(0, none.height, 2))


def test_pits_found_are_barriers_and_the_route_takes_their_one_gap_then_replans_when_it_closes():
    """seed 1.2.2 / 3.3.2: a line of pits across the room (cells a foot found no ground on) with one gap: the
    route uses the gap; once pits are found in the gap too the map has changed and there is no way."""
    m = new_map(ROOM_POLY)
    for pose in POSES:
        m.add_scan(scan(ROOM, *pose))

    def pits(y0: float, y1: float) -> None:
        for k in range(int((y1 - y0) / 0.05) + 1):
            for x in (2.9, 3.0, 3.1):
                m.grid.mark_barrier(x, y0 + 0.05 * k)

    start, goal = (1.2, 1.5), (4.8, 1.5)
    m.rebuild()
    direct = m.route(start, goal)
    assert direct is not None and max(p[1] for p in direct) < 3.0        # open room: nearly straight across
    pits(0.0, 4.4)                                                        # the gap: y 4.4 .. 6 (the wall)
    m.add_scan(scan(ROOM, 1.5, 1.5, 0))                                   # a new echo cannot clear a pit
    m.rebuild()
    around = m.route(start, goal)
    assert around is not None
    legs = list(zip([start] + around, around))
    crossing = [(a, b) for a, b in legs if (a[0] < 3.0) != (b[0] < 3.0)]
    assert crossing and all(min(a[1], b[1]) > 4.4 for a, b in crossing)  # through the gap only
    pits(4.4, 6.0)                                                        # pits found in the gap too
    m.rebuild()
    assert m.route(start, goal) is None


def strip_map() -> TopoMap:
    """A free strip x 0.5..4.8 along y = 1 between two lines of pits (x 0.2..3.6), open onto unknown space at
    both ends."""
    g = OccupancyGrid(-1.0, -1.0, 8.0, 4.0, 0.1)
    for k in range(81):
        g.mark_free(0.5 + 0.05 * k, 1.0, 0.3)
    for k in range(69):
        g.mark_barrier(0.2 + 0.05 * k, 0.6)
        g.mark_barrier(0.2 + 0.05 * k, 1.4)
    m = TopoMap(g, robot_radius_m=0.16, place_spacing_m=0.5)
    m.rebuild()
    return m


def test_frontier_target_is_kept_until_not_approached_then_given_up_for_good():
    """seed 3.3.2: the robot keeps to the frontier it chose although another one became nearer, gives it up
    when its route has not shortened for the patience time, and then never chooses it again."""
    m = strip_map()
    ft = FrontierTarget(exclude_m=0.5, progress_m=0.3, patience_s=40.0)
    route = ft.route(m, 1.5, 1.0, 0.0, reached_m=0.2, min_size=3)
    first = ft.target
    assert route and first is not None and first[0] < 0.6 and route[-1] == first   # the near (left) end
    route = ft.route(m, 2.8, 1.0, 10.0, reached_m=0.2, min_size=3)                  # now the right end is nearer
    assert ft.target == first and route[-1] == first                                  # kept
    route = ft.route(m, 2.8, 1.0, 41.0, reached_m=0.2, min_size=3)                  # not approached for 41 s
    assert ft.given_up == [first] and ft.target is not None and ft.target[0] > 3.5 and route[-1] == ft.target
    ft.target = None                                                                  # a fresh choice near the
    ft.route(m, 1.5, 1.0, 50.0, reached_m=0.2, min_size=3)                          # left end: not the given-up one
    assert ft.target is not None and ft.target[0] > 3.5
    right = ft.target
    ft.route(m, right[0] - 0.4, right[1], 60.0, reached_m=0.2, min_size=3)          # within 0.5 m: reached
    assert ft.given_up == [first, right] and ft.target != right


def test_frontier_target_replans_round_pits_found_on_the_way_and_ends_when_explored():
    """seed 1.2.2 / 3.3.2: pits found across the way to the target refute it (no route is left): the next
    frontier is taken at once; once that end is explored too, nothing is left to explore."""
    m = strip_map()
    ft = FrontierTarget(exclude_m=0.5, progress_m=0.3, patience_s=40.0)
    ft.route(m, 1.5, 1.0, 0.0, reached_m=0.2, min_size=3)
    left = ft.target
    for k in range(9):                                   # a foot finds no ground across the strip at x = 1.0
        m.grid.mark_barrier(1.0, 0.6 + 0.1 * k)
    m.rebuild()
    route = ft.route(m, 1.5, 1.0, 5.0, reached_m=0.2, min_size=3)
    assert ft.given_up == [left] and ft.target is not None and ft.target[0] > 3.5
    assert route and all(p[0] > 1.0 for p in route)                                    # never through the pits
    for k in range(131):                                 # all seen: walls round x 0..6.5, y -0.5..2.5 ...
        m.grid.mark_barrier(0.05 * k, -0.5)
        m.grid.mark_barrier(0.05 * k, 2.5)
    for k in range(61):
        m.grid.mark_barrier(0.0, -0.5 + 0.05 * k)
        m.grid.mark_barrier(6.5, -0.5 + 0.05 * k)
    for i in range(64):                                  # ... and free inside (pits stay pits)
        for j in range(29):
            m.grid.mark_free(0.05 + 0.1 * i, -0.45 + 0.1 * j, 0.05)
    m.rebuild()
    assert not m.frontier_near(*ft.target, 0.5)
    assert ft.route(m, 4.0, 1.0, 10.0, reached_m=0.2, min_size=3) == [] and ft.target is None


def test_a_route_out_of_a_ring_of_pits_takes_its_one_gap():
    """pit_ring's ring (scenarios/pit_ring.yaml) as the feet found it: from the start at its centre
    the route to a point outside leaves through the 0.8 m gap on the east side, whatever side the goal is on."""
    room = box(0, 0, 6, 4)
    m = TopoMap(OccupancyGrid(-0.5, -0.5, 7.0, 5.0, 0.1), robot_radius_m=0.16, place_spacing_m=0.5)
    for pose in ((3.0, 2.0, 90), (1.0, 0.5, 0), (5.0, 3.5, 0)):
        m.add_scan(scan(room, *pose))
    edge = 0.05
    for k in range(int(2.8 / edge) + 1):                 # the ring's inner edges, as the feet found them
        x = 1.6 + 0.4 + k * edge * (2.0 / 2.8)
        m.grid.mark_barrier(x, 1.0)                      # south
        m.grid.mark_barrier(x, 3.0)                      # north
    for k in range(int(2.0 / edge) + 1):
        y = 1.0 + k * edge
        m.grid.mark_barrier(2.0, y)                      # west
        if not 1.6 < y < 2.4:
            m.grid.mark_barrier(4.0, y)                  # east, but for the gap
    m.rebuild()
    for goal in ((0.8, 2.0), (3.0, 0.4), (5.2, 2.0)):
        route = m.route((3.0, 2.0), goal)
        assert route is not None and route[-1] == goal
        legs = list(zip([(3.0, 2.0)] + route, route))
        out = [(a, b) for a, b in legs if (2.0 < a[0] < 4.0 and 1.0 < a[1] < 3.0)
               != (2.0 < b[0] < 4.0 and 1.0 < b[1] < 3.0)]
        assert len(out) == 1 and out[0][1][0] >= 4.0 and 1.6 < (out[0][0][1] + out[0][1][1]) / 2 < 2.4
    for k in range(9):                                   # the gap found too: no way out
        m.grid.mark_barrier(4.0, 1.6 + 0.1 * k)
    m.rebuild()
    assert m.route((3.0, 2.0), (5.2, 2.0)) is None


def _ring_map(place_spacing_m: float) -> TopoMap:
    """pit_ring's room as the sonar sees it (over the pits: it sees no hole), and the ring's inner edges as the
    feet found them, but for the 0.8 m gap on the east side (1.6 < y < 2.4)."""
    m = TopoMap(OccupancyGrid(-0.5, -0.5, 7.0, 5.0, 0.1), robot_radius_m=0.16, place_spacing_m=place_spacing_m)
    for pose in ((3.0, 2.0, 90), (1.0, 0.5, 0), (5.0, 3.5, 0)):
        m.add_scan(scan(box(0, 0, 6, 4), *pose))
    for k in range(41):
        x, y = 2.0 + k * 0.05, 1.0 + k * 0.05
        m.grid.mark_barrier(x, 1.0)
        m.grid.mark_barrier(x, 3.0)
        m.grid.mark_barrier(2.0, y)
        if not 1.6 < y < 2.4:
            m.grid.mark_barrier(4.0, y)
    m.rebuild()
    return m


def _inside_ring(p: tuple[float, float]) -> bool:
    return 2.0 < p[0] < 4.0 and 1.0 < p[1] < 3.0


def test_a_route_out_leaves_a_ring_of_pits_through_its_gap():
    """seed 3.3.2, issue 17: with no goal point, only a radius round the ring's middle to get beyond, the route
    out over the grid's cells leaves through pit_ring's gap, in straight stretches the robot's disc fits along."""
    m = _ring_map(place_spacing_m=1.0)
    route = m.route_out((3.0, 2.0), (3.0, 2.0), 1.9, [], 0.6, 4.0)
    assert route is not None and math.dist(route[-1], (3.0, 2.0)) > 1.9 and route[-1][0] > 4.4
    legs = list(zip([(3.0, 2.0)] + route, route))
    out = [(a, b) for a, b in legs if _inside_ring(a) != _inside_ring(b)]
    assert len(out) == 1 and out[0][1][0] >= 4.0
    assert all(m.passable(a, b) for a, b in legs[1:])
    for k in range(9):                                   # the gap found too: no way out
        m.grid.mark_barrier(4.0, 1.6 + 0.1 * k)
    m.rebuild()
    assert m.route_out((3.0, 2.0), (3.0, 2.0), 1.9, [], 0.6, 4.0) is None


def test_a_route_out_keeps_clear_of_the_pits_found_when_it_can():
    """CHOICE (TopoMap.route_out): a pit's edge runs on past what the feet found, so the way out is wary of the
    ground near the pit cells found: with them costing more it leaves further from them than the shortest way,
    which runs round the end of the stretch found."""
    m = TopoMap(OccupancyGrid(-0.5, -0.5, 7.0, 5.0, 0.1), robot_radius_m=0.16, place_spacing_m=1.0)
    m.add_scan(scan(box(0, 0, 6, 4), 3.0, 2.0))
    pits = [(2.0 + 0.05 * k, 1.0) for k in range(41)]          # the south edge, found from x 2 to 4
    for p in pits:
        m.grid.mark_barrier(*p)
    m.rebuild()
    near = lambda route: min(math.dist(w, p) for w in route for p in pits)          # noqa: E731
    bold = m.route_out((3.0, 1.4), (3.0, 2.0), 1.4, pits, 0.6, 0.0)
    wary = m.route_out((3.0, 1.4), (3.0, 2.0), 1.4, pits, 0.6, 4.0)
    assert bold is not None and wary is not None
    assert near(bold) < 0.6 <= near(wary)


def test_occupied_near_lists_the_occupied_cells_within_the_radius():
    g = OccupancyGrid(0.0, 0.0, 4.0, 4.0, 0.1)
    g.integrate(Reading(1.0, 2.0, 0.0, 0.0, 0.8))             # an echo 0.8 m east of (1, 2)
    g.mark_barrier(1.0, 3.5)                                   # a pit edge 1.5 m north
    near = g.occupied_near(1.0, 2.0, 1.0)
    assert len(near) == 1 and abs(near[0][0] - 1.85) < 0.11 and abs(near[0][1] - 2.0) < 0.1
    assert any(abs(y - 3.55) < 0.1 for _x, y in g.occupied_near(1.0, 2.0, 1.6))


def cone_echo(walls: list[Segment], x: float, y: float, bearing: float, cone_deg: float = 15.0) -> float | None:
    """The sonar's echo: the nearest wall over 5 rays across its cone (as sim2d's transducer sees it)."""
    hits = [cast(walls, x, y, bearing + math.radians(-cone_deg / 2 + cone_deg * k / 4)) for k in range(5)]
    return min((h for h in hits if h is not None), default=None)


def votes_for(m: TopoMap, x: float, y: float, true_deg: float, believed_deg: float) -> list[float]:
    """heading_offset's votes (deg) for echoes of ROOM every 10 deg round a robot that believes `believed_deg`."""
    out = []
    for head in range(0, 360, 10):
        d = cone_echo(ROOM, x, y, math.radians(true_deg + head))
        off = heading_offset(m.grid, x, y, math.radians(believed_deg + head), d, 15.0, 5, 10, 0.08, 6)
        if off is not None:
            out.append(math.degrees(off))
    return out


@pytest.mark.parametrize("error_deg", [-6.0, 0.0, 4.0])
def test_echoes_of_mapped_walls_vote_for_the_heading_that_fits_the_map(square_room, error_deg):
    votes = votes_for(square_room, 2.0, 2.5, 30.0, 30.0 - error_deg)
    assert len(votes) >= 8                              # the walls seen at a slant can tell
    assert statistics.median(votes) == pytest.approx(error_deg, abs=1.5)


def test_a_wall_seen_square_on_or_ground_the_map_does_not_know_cannot_tell(square_room):
    g = square_room.grid
    d = cone_echo(ROOM, 3.0, 3.0, 0.0)                  # the east wall, square on from the room's middle
    assert heading_offset(g, 3.0, 3.0, 0.0, d, 15.0, 5, 10, 0.08, 6) is None
    blank = new_map().grid                              # nothing mapped yet
    assert heading_offset(blank, 2.0, 2.5, math.radians(20), 2.0, 15.0, 5, 10, 0.08, 6) is None


def test_heading_votes_correct_by_a_share_of_their_median_at_most_a_step_at_a_time():
    v = HeadingVotes(count=3, gain=0.5, max_step=math.radians(2.0))
    assert v.add(math.radians(2.0)) == 0.0 and v.add(math.radians(3.0)) == 0.0
    assert math.degrees(v.add(math.radians(-9.0))) == pytest.approx(1.0)     # median 2, half of it
    assert v.add(math.radians(10.0)) == 0.0                                  # counted afresh
    v.add(math.radians(10.0))
    assert math.degrees(v.add(math.radians(10.0))) == pytest.approx(2.0)     # clipped to the step


def junction_map() -> TopoMap:
    """A free strip west-east along y = 1 (x -1.0 .. 3.0, open to the west) into a north-south one at x = 3.0
    (y -1.0 .. 3.0, open at both ends), lined with barriers: three frontiers, two behind the junction."""
    g = OccupancyGrid(-2.0, -2.0, 8.0, 7.0, 0.1)
    for k in range(81):
        g.mark_free(-1.0 + 0.05 * k, 1.0, 0.3)
        g.mark_free(3.0, -1.0 + 0.05 * k, 0.3)
    for k in range(69):
        g.mark_barrier(-0.8 + 0.05 * k, 0.6)
        g.mark_barrier(-0.8 + 0.05 * k, 1.4)
    for k in range(29):
        for y0 in (-0.8, 1.4):
            g.mark_barrier(2.6, y0 + 0.05 * k)
            g.mark_barrier(3.4, y0 + 0.05 * k)
    for k in range(17):
        g.mark_barrier(3.4, 0.6 + 0.05 * k)
    m = TopoMap(g, robot_radius_m=0.16, place_spacing_m=0.5)
    m.rebuild()
    return m


def test_frontiers_behind_a_waypoint_the_robot_could_not_get_past_are_given_up_at_once():
    """light_behind_wall seed 5 (an earlier branch): the frontiers it chose one after another lay behind the same
    unreachable waypoint, 40 s each. Once the target beyond the junction is given up (not approached), the other
    frontier beyond it goes too, and the one the other way is the target at once."""
    m = junction_map()
    ft = FrontierTarget(exclude_m=0.5, progress_m=0.3, patience_s=40.0)
    ft.route(m, 2.0, 1.0, 0.0, reached_m=0.2, min_size=3)
    first = ft.target
    assert first is not None and first[0] > 2.5                                    # beyond the junction
    route = ft.route(m, 2.0, 1.0, 41.0, reached_m=0.2, min_size=3)                # stuck before it for 41 s
    assert ft.target is not None and ft.target[0] < -0.5 and route[-1] == ft.target   # the west end
    assert all(p[0] < 2.0 for p in route)
    beyond = [p for p in ft.given_up if p[0] > 2.5]
    assert any(p[1] > 2.0 for p in beyond) and any(p[1] < 0.0 for p in beyond)    # north and south ends
    while ft.target is not None and ft.target[0] < 2.5:                             # the west end given up too:
        ft.given_up.append(ft.target)                                               # nothing left but what is
        ft.target = None                                                            # behind the junction ...
        ft.route(m, 2.0, 1.0, 50.0, reached_m=0.2, min_size=3)
    assert ft.stuck == [] and ft.target is not None and ft.target[0] > 2.5          # ... tried again (start over)


def test_a_waypoint_the_robot_could_not_get_past_is_forgotten_once_it_is_elsewhere():
    """Stuck before the junction is where it was stuck: 0.2 m off, the route beyond it is not taken; 1.2 m back
    west with the west end explored (another way may lead past it now, the map has grown), it is."""
    m = junction_map()
    stuck = Stuck(waypoint=(2.55, 1.05), at=(2.0, 1.0))
    near = FrontierTarget(exclude_m=0.5, progress_m=0.3, patience_s=40.0, stuck=[stuck])
    near.route(m, 1.8, 1.0, 0.0, reached_m=0.2, min_size=3)
    assert near.target is not None and near.target[0] < -0.5 and near.stuck == [stuck]
    west = [(-0.95, 1.25), (-0.95, 0.75)]                                          # the west end explored
    away = FrontierTarget(exclude_m=0.5, progress_m=0.3, patience_s=40.0, given_up=list(west), stuck=[stuck])
    away.route(m, 0.8, 1.0, 0.0, reached_m=0.2, min_size=3)
    assert away.target is not None and away.target[0] > 2.5 and away.stuck == [] and away.given_up == west
