"""NP3 (seed 3.2.3, 3.3.2, 5.1-5.2, 6): navigation as a subsumption network (docs/decisions.md D8).

The node owns the network of behaviours.np3_layers and evaluates it every
NP3 period (and at once after a record that may need a reflex, 5.2). Its
sensor registers are filled ONLY from the DATA records the MCP delivers
(address = source node, kind VALUE / ALARM / STATUS, channel, value in the
source's XMIT_DATA encoding, decoded with the spec's conversions). The
actuator "move" leaves as a MOVE record through the MCP's message
scheduling (3.2.2): XMIT_REQ, then MOVE when the MCP grants the bus.

Beside the network the node keeps a dead-reckoned pose (CHOICE: its own MOVE
commands walked through a copy of the MMC's gait generator, GaitReckoning, so
a turn's re-phase pauses count) and the topological map of
seed 3.3.2, built from the USRC's echoes (channel = head angle). The tasks that
plan on the map correct the pose's heading from it: echoes of mapped surfaces
vote for the heading under which the map predicts them (topomap.HeadingVotes;
no compass is declared, and the behaviours never read the simulator's pose); exploring
heads along the map's least-passed open ray. A short local memory of echoes
(sonar, IR, whiskers) at the DR pose lets wall following and avoidance see
what the sensors saw seconds ago. debug_metrics() reports which layer held the
MMC for how long; write_artifacts() writes control.tsv, topomap.png and plans.tsv (every plan, DR frame).
"""
from __future__ import annotations

import math
from collections import deque
from pathlib import Path
from typing import Any, Mapping, NamedTuple, TypedDict, TypeVar

from arachnae_proto import messages as M
from arachnae_proto.enums import MmcError, MovCmd, RangeStatus, RecordKind, TpscContact
from arachnae_proto.network import ADDRESS_OF, NODES
from arachnae_proto.skeletons.np3 import Np3Skeleton

from behaviours import tuning as T
from behaviours.gait import FIVE_LEGGED, STILL, Gait
from behaviours.geometry import FeelerArm, RobotGeometry, along, mirrored
from behaviours.np3_layers import (AVOIDANCE, REFLEXES, PinnedCheck, TaskModule, Tuning, body_frame, closing_in,
                                   np3_network, safe_instead, steepness_deg, uphill)
from behaviours.runtime import Runtime
from behaviours.topomap import (OCCUPIED, FrontierTarget, HeadingVotes, OccupancyGrid, Reading, TopoMap, heading_offset,
                                ray_cells)
from behaviours.units import RECORD_AGE, RECORD_QUANTIZER, Quantizer, from_record_byte

_VALUE, _ALARM, _STATUS = int(RecordKind.VALUE), int(RecordKind.ALARM), int(RecordKind.STATUS)
_IR_BAD = {int(RangeStatus.UNRELIABLE), int(RangeStatus.OUT_OF_ORDER)}
_NO_GROUND, _BLOCKED = int(MmcError.NO_GROUND), int(MmcError.LEG_DRIVE_BLOCKED)
_LEG_LOST = {int(MmcError.LCP_OUT_OF_ORDER), int(MmcError.JAC_OUT_OF_ORDER)}
_STOP, _FORWARD, _BACKWARD = int(MovCmd.STOP), int(MovCmd.FORWARD), int(MovCmd.BACKWARD)
_LEFT, _RIGHT = int(MovCmd.TURN_LEFT), int(MovCmd.TURN_RIGHT)
_SIDE_L, _SIDE_R = int(MovCmd.SIDESTEP_LEFT), int(MovCmd.SIDESTEP_RIGHT)
# the encoding each source role's records carry (spec messages.<m>.record_values)
_Q: dict[str, Quantizer] = RECORD_QUANTIZER
_PLANNING = ("explore", "seek_light")      # the tasks that plan routes over the map (3.3.2) and so keep it true


def decode(role: str, value: int) -> float:
    """A record's value byte in the physical unit of `role`'s XMIT_DATA field (signed fields: two's complement)."""
    q = _Q[role]
    return q.phys(from_record_byte(value, q.lo < 0))


def wrap_angle(a: float) -> float:
    """An angle in rad brought to [-pi, pi)."""
    return (a + math.pi) % (2 * math.pi) - math.pi


def displaced(x: float, y: float, th: float, fwd_m: float, left_m: float,
              turn_rad: float) -> tuple[float, float, float]:
    """The pose after the body moved this far in its own frame (turning about its middle while it went)."""
    a = th + turn_rad / 2
    return (x + fwd_m * math.cos(a) - left_m * math.sin(a), y + fwd_m * math.sin(a) + left_m * math.cos(a),
            wrap_angle(th + turn_rad))


class Leg(NamedTuple):
    """A stretch of dead reckoning: from time t at pose (x, y, th) the robot did cmd."""
    t: float
    x: float
    y: float
    th: float
    cmd: int


class Echo(NamedTuple):
    """An obstacle point of the local memory, in world (DR) terms: seen at body angle seen_deg, somewhere within
    arc_m across the beam; `sonar`: a point of a sonar echo's cone (a later ping's free space may clear it)."""
    t: float
    x: float
    y: float
    seen_deg: float
    arc_m: float
    sonar: bool = False

    def point(self) -> tuple[float, float, float, float]:
        """What the network's `echoes` register holds per point."""
        return self.x, self.y, self.seen_deg, self.arc_m


class Ping(NamedTuple):
    """A sonar ping as free space (issue 17): from (x, y) along world bearing `bearing` nothing nearer than
    `reach` m across the cone (its nearest echo, or the sonar's range when none came back)."""
    t: float
    x: float
    y: float
    bearing: float
    reach: float

    def clears(self, px: float, py: float) -> bool:
        """The point lies inside this ping's cone clearly nearer than its echo. The whole beam: the echo is the
        nearest reflector anywhere across it, and the ping 15 deg on shares its edge with this one, where its cone's
        inner point lies (with 6 deg the sweep's 0 / +-15 deg pings never cleared each other's edge points: in
        corridor_narrow they stayed 0.085 m off the axis 0.65 m ahead, seeds 3 and 4 turned into the walls)."""
        dx, dy = px - self.x, py - self.y
        off = wrap_angle(math.atan2(dy, dx) - self.bearing)
        return (abs(off) <= math.radians(T.NP3_SONAR_BEAM_DEG / 2) + 1e-9
                and math.hypot(dx, dy) < self.reach - T.NP3_SONAR_CARVE_TOL_M)


_World = TypeVar("_World", Leg, Echo, Ping)


def turned_about(rec: _World, cx: float, cy: float, turn: float) -> _World:
    """A record in world (DR) terms turned by `turn` rad about (cx, cy): its point, and its world direction (a
    leg's heading, a ping's bearing) with it; an echo's seen_deg is relative to the body and stays."""
    c, s = math.cos(turn), math.sin(turn)
    dx, dy = rec.x - cx, rec.y - cy
    x, y = cx + dx * c - dy * s, cy + dx * s + dy * c
    if isinstance(rec, Leg):
        return rec._replace(x=x, y=y, th=wrap_angle(rec.th + turn))
    if isinstance(rec, Ping):
        return rec._replace(x=x, y=y, bearing=wrap_angle(rec.bearing + turn))
    return rec._replace(x=x, y=y)


class DeadReckoning:
    """The pose the NP3 believes in: its own MOVE commands at the gait's measured speeds (CHOICE, no odometry).
    The last seconds of the pose are kept as legs (issue 17), so the pose at an earlier time (a sonar ping's) is
    known too: a leg is where the pose stood at its time, and `moved` carries it on from there. Here a leg starts
    at each command and the constant rates carry it; GaitReckoning keeps one a gait step."""

    def __init__(self, speed_m_s: float, turn_rad_s: float, side_m_s: float | None = None) -> None:
        self.x = self.y = self.th = 0.0
        self.speed, self.turn = speed_m_s, turn_rad_s
        self.side = speed_m_s if side_m_s is None else side_m_s
        self.cmd = _STOP
        self.t: float | None = None
        self.legs: deque[Leg] = deque()

    def moved(self, x: float, y: float, th: float, cmd: int, dt: float) -> tuple[float, float, float]:
        """The pose after doing `cmd` for dt seconds from (x, y, th) at the constant rates."""
        v = self.speed if cmd == _FORWARD else -self.speed if cmd == _BACKWARD else 0.0
        u = self.side if cmd == _SIDE_L else -self.side if cmd == _SIDE_R else 0.0
        w = self.turn if cmd == _LEFT else -self.turn if cmd == _RIGHT else 0.0
        return displaced(x, y, th, v * dt, u * dt, w * dt)

    def advance(self, now: float) -> None:
        dt = 0.0 if self.t is None else max(0.0, now - self.t)
        self.t = now
        self.x, self.y, self.th = self.moved(self.x, self.y, self.th, self.cmd, dt)

    def keep(self, now: float) -> None:
        """A leg from the pose now; the history reaches NP3_POSE_HISTORY_S back (the leg running then included)."""
        self.legs.append(Leg(now, self.x, self.y, self.th, self.cmd))
        while len(self.legs) > 1 and now - self.legs[1].t > T.NP3_POSE_HISTORY_S:
            self.legs.popleft()

    def command(self, now: float, cmd: int) -> None:
        self.advance(now)
        if cmd < int(MovCmd.TRIPOD):            # a direction; 7..9 only change the gait
            self.cmd = cmd
            self.keep(now)

    def leg_lost(self, now: float, leg: int) -> None:
        """A leg is out of order (seed 6.3): the constant rates do not know how fast five legs walk."""

    def pose_at(self, t: float) -> tuple[float, float, float]:
        """The pose at time t (not after the last advance): on the leg running then (issue 17)."""
        if self.t is None or t >= self.t:
            return self.pose
        leg = next((g for g in reversed(self.legs) if g.t <= t), None)
        if leg is None:                         # before the history (or before any command): its start
            first = self.legs[0] if self.legs else None
            return (first.x, first.y, first.th) if first else self.pose
        return self.moved(leg.x, leg.y, leg.th, leg.cmd, t - leg.t)

    def turn_heading(self, turn: float) -> None:
        """The heading was `turn` rad off (the map says so, 3.3.2): the pose turns by it about where the robot
        stands, and the kept legs with it, so that a pose_at(t) after the correction is in the same frame."""
        self.th = wrap_angle(self.th + turn)
        self.legs = deque(turned_about(g, self.x, self.y, turn) for g in self.legs)

    @property
    def pose(self) -> tuple[float, float, float]:
        return self.x, self.y, self.th


class GaitReckoning(DeadReckoning):
    """Dead reckoning through the gait's own geometry (CHOICE, no odometry): the NP3 walks a copy of the MMC's
    gait generator (behaviours.gait, the same model, seed 3.2.3) through the MOVEs it sends and adds up how
    far the stance feet carry the body, times the share the feet hold on the ground (`grip`, `turn_grip`).

    Why: a constant turn rate (22.5 deg/s) was wrong by the phase a turn starts in: the gait re-phases after
    a start or a turn, and a stance foot at its stroke's end holds the body until it has stepped, so a turn
    after walking turned 8.8-23 deg/s over its first seconds (issue 17: the heading ended 16-74 deg off).
    The model has those pauses; the sensors are not needed for it, and the simulator's pose is not read.
    What the MMC does on its own the copy does when the MMC's STATUS tells (NP3.stopped_by_mmc, leg_lost).
    Not modelled (issue 17, s10-heading): feet sliding along an obstacle's face turn the body with no report
    to the NP3 (seek_light seed 4 at 71-78 s: +67 deg while walking FORWARD, the sim's blocked-foot count
    21 -> 55, no LEG_DRIVE_BLOCKED relayed, no heading vote): only the map can tell that.
    The history: a leg after each gait step that moved the body; its rates are zero, so between two steps
    (one MMC control period) the pose holds.
    """

    def __init__(self, geometry: RobotGeometry, grip: float, turn_grip: Mapping[str, float], step_s: float) -> None:
        super().__init__(0.0, 0.0, 0.0)
        self.gait = Gait(geometry)
        self.grip, self.step_s = grip, step_s
        self.footless = False       # seed 1.2.2: a foot stands over a pit (the MMC's NO_GROUND, till it clears)
        self.turn_grips = {int(MovCmd[name]): g for name, g in turn_grip.items()}
        self.turn_grips[FIVE_LEGGED] = self.turn_grips[int(MovCmd.WAVE)]      # seed 6.3: a wave over five legs

    @property
    def turn_grip(self) -> float:
        """The share of the running pattern's turn the body makes (measured per gait: a tripod's three stance feet
        slip more than a ripple's or a wave's four or five)."""
        return self.turn_grips[self.gait.running]

    def advance(self, now: float) -> None:
        if self.t is None:
            self.t = now
        while self.t + self.step_s / 2 <= now:            # the MMC's control period, whole steps
            self.t += self.step_s
            self.gait.advance(self.step_s)
            m = self.gait.moved
            if m is not STILL:
                lost = T.NP3_DR_FOOTLESS_GRIP if self.footless else 1.0
                self.x, self.y, self.th = displaced(self.x, self.y, self.th, m.fwd_m * self.grip * lost,
                                                    m.left_m * self.grip * lost, m.turn_rad * self.turn_grip * lost)
                self.keep(self.t)

    def command(self, now: float, cmd: int) -> None:
        super().command(now, cmd)
        self.gait.set_command(cmd)                      # a gait (7..9) too: it changes the stroke's timing

    def leg_lost(self, now: float, leg: int) -> None:
        """seed 6.3: the MMC walks on five legs (its STATUS says a leg is out of order): so does the copy."""
        self.advance(now)
        self.gait.drop_leg(leg)


class OpenHeading(NamedTuple):
    """explore's best ray through the map (NP3.open_heading)."""
    score: float
    heading: float          # rad, DR frame
    free_m: float           # free length before a mapped obstacle
    fresh_m: float          # of it, not yet passed


class HeadingPlan(NamedTuple):
    """explore's heading goal as set: judged at the next plan (NP3.not_approached)."""
    x: float
    y: float
    heading: float
    goal: tuple[float, float]
    left_m: float                 # the goal's distance when set
    fights: int                   # times a stronger layer had taken the actuator by then


class RingOut(NamedTuple):
    """A ring of pits round the robot (NP3.ringed): its middle (DR frame) and how far from it the outside begins."""
    x: float
    y: float
    radius: float


class PlanRecord(NamedTuple):
    """One task-layer decision (seed 3.3.2), kept for plans.tsv: where the robot thought it was, what it chose."""
    t: float
    x: float
    y: float
    kind: str                               # "heading" (the map's least-passed open ray), "frontier" (a route),
                                            # "out" (a route out of a ring of pits), "none"
    fresh_m: float                          # the best heading's not-yet-passed length (explore; 0 otherwise)
    route: tuple[tuple[float, float], ...]  # the waypoints planned, the goal last


class Np3Map(TypedDict):
    places: int
    edges: int
    routes: int
    routes_out: int               # of them, routes out of a ring of pits (NP3.ringed)
    rings_left: int               # times the robot stood beyond the pits that hemmed it in
    pit_cells: int                # map cells a foot's NO_GROUND marked
    seen_m2: float
    heading_fixed_deg: float      # the heading corrections from the map, summed


class Np3Light(TypedDict, total=False):      # empty before the first light reading
    first_lux: float
    last_lux: float
    ratio: float


class Np3Debug(TypedDict, total=False):      # control, switches and moves_sent only, before navigation starts
    """NP3.debug_metrics(): metrics.json `nodes.NP3` (sim2d.metrics checks expectations on it at load)."""
    control: dict[str, float]       # layer -> seconds it held the MMC
    switches: int
    takeovers: dict[str, int]       # reflex -> times it took over
    moves_sent: int
    records: int
    pose: list[float]
    battery_low: bool
    ir_fault: bool
    sonar_ignored: bool
    map: Np3Map
    light: Np3Light


class NP3(Runtime, Np3Skeleton):
    def start(self) -> None:
        g = self.cfg.geometry
        self.running = False
        self.tuning = Tuning()
        self.layers = np3_network(lambda: self.now, self.cfg.task, self.tuning)
        # every task reckons through the gait model (issue 17, s10-heading: exp9's obstacle_course seed 5 and
        # worst_contention seed 4, which failed with it on s9-light, pass; bench/dr_heading.py measures it)
        self.odo: DeadReckoning = GaitReckoning(g, T.NP3_DR_GRIP, T.NP3_DR_TURN_GRIP, T.MMC_CONTROL_S)
        self.geo = g
        self.echoes: deque[Echo] = deque()
        self.pings: deque[Ping] = deque()                 # the sonar's recent free space (issue 17)
        half = T.NP3_MAP_SIZE_M / 2
        self.map = TopoMap(OccupancyGrid(-half, -half, 2 * half, 2 * half, T.NP3_MAP_CELL_M),
                           robot_radius_m=g.body_width, place_spacing_m=1.0)
        self.body_r = g.body_width / 2
        self.pending: int | None = None       # the latest wish, waiting for the MCP's grant
        self.sent_module = ""
        self.doubt = False
        self.requested = False
        self.sent: tuple[int, str] | None = None   # (command, module) of the last MOVE
        self.moves_sent = 0
        self.holder = ""                      # module holding the actuator after the last step
        self.takeovers: dict[str, int] = {}
        # registers and what the records told so far
        self.ir: list[float | None] = [None, None, None]
        self.heard: set[str] = set()          # roles that sent a record since power-on
        self.look_until = math.inf            # no step before the IR and whiskers reported, or until then (seed 5.2)
        self.tilt = [0.0, 0.0]
        self.touch_at, self.touch_side = -math.inf, 0.0   # the last single-feeler touch: when, side (+1 left)
        self.seq = {"whisker": 0, "pit": 0, "leg_blocked": 0, "light": 0, "sound": 0, "veto": 0, "pinned": 0}
        self.pinned = PinnedCheck(self.tuning)        # issue 17: the body held by something no sensor sees
        self.escape_plans: dict[str, Any] = {}   # module -> its manoeuvre last noted as an escape window (5.2)
        self.mmc_error = (0, 0)
        self.battery_low = False
        self.ir_fault = False
        self.sonar_ignored = False
        self.sonar_ahead: tuple[float, float] | None = None    # (time, metres)
        self.records = 0
        self.lux: list[float] = []
        self.next_plan = 0.0
        self.planned_at = -math.inf           # the last full plan (a rebuilt map): at most one per NP3_PLAN_CHANGED_S
        self.goal: tuple[float, float] | None = None
        self.routes_planned = 0               # routes planned over the topological map (3.3.2)
        self.routes_out = 0                   # ... of them out of a ring of pits
        self.rings_left = 0                   # times the robot stood beyond the pits that hemmed it in (ringed)
        self.pit_cells: dict[tuple[int, int], tuple[float, float]] = {}   # map cell -> point a pit's edge marked
        self.pits_met = 0                     # pit edges the feet found (mark_pit) since the robot last left a ring
        self.ring: RingOut | None = None      # the pits found hem the robot in (ringed): the ring's middle
        self.frontier_target = FrontierTarget(T.NP3_PLAN_EXCLUDE_M, T.NP3_PLAN_PROGRESS_M, T.NP3_PLAN_PATIENCE_S)
        self.plans: list[PlanRecord] = []     # every full plan, for plans.tsv (what was planned vs what happened)
        self.heading_plan: HeadingPlan | None = None
        self.blocked: deque[HeadingPlan] = deque(maxlen=T.NP3_EXPLORE_BLOCKED_KEEP)   # headings not approached
        self.visited: set[tuple[int, int]] = set()
        self.heading_votes = HeadingVotes(T.NP3_MATCH_VOTES, T.NP3_MATCH_GAIN, math.radians(T.NP3_MATCH_STEP_DEG))
        self.heading_fixed = 0.0              # the heading corrections from the map, summed (rad, debug metrics)
        self.last_cell: tuple[int, int] | None = None
        self.every(T.NP3_PERIOD_S, self.tick)

    def on_init(self, src: int, msg: M.Init) -> None:
        """seed 3.2.3: INIT from the MCP after POST starts navigation with a zeroed world model."""
        if not self.running:
            self.running = True
            self.look_until = self.now + T.NP3_START_LOOK_S
            # seed 6.3: after POST the legs stand (the MMC holds them), so a task that wants STOP has nothing
            # to say; sending it anyway overrode an operator's MOVE typed right after POST (3.2.8: the RCP's commands)
            if self.sent is None:
                self.sent = (_STOP, "task")
            self.hw.note("nav_start")          # 5.2: from here on the robot can act on what it senses
            self.tick()

    # --- the network, every period ---------------------------------------------------------
    def tick(self) -> None:
        if not self.running:
            return
        now = self.now
        self.odo.advance(now)
        x, y, th = self.odo.pose
        self.map.grid.mark_free(x, y, self.body_r)
        self.map.visit(x, y)
        ahead = self.sonar_ahead
        fresh = ahead is not None and now - ahead[0] <= T.NP3_SONAR_FRESH_S and not self.sonar_ignored
        while self.echoes and now - self.echoes[0].t > T.NP3_ECHO_KEEP_S:
            self.echoes.popleft()
        self.layers.sense(pose=(x, y, th), sonar_ahead_m=ahead[1] if fresh else None,
                          echoes=tuple(e.point() for e in self.echoes))
        if self.cfg.task in ("explore", "seek_light", "avoid_light"):   # the tasks that detour (TaskModule._detour)
            g = self.map.grid
            self.layers.sense(mapped=tuple((mx, my, 0.0, g.res / 2)
                                           for mx, my in g.occupied_near(x, y, T.NP3_MAPPED_NEAR_M)))
        if self.cfg.task in _PLANNING:                   # seeking light explores while it is dark
            self.mark_visited(x, y)
            goal = self.goal
            if now >= self.next_plan or (goal is not None and math.hypot(goal[0] - x, goal[1] - y)
                                         < T.NP3_GOAL_REACHED_M):
                self.plan_goal(now)
        if not self.heard.issuperset(T.SPU_FIRST_POLL) and now < self.look_until:
            return       # seed 5.2: switched on next to a wall, the first step waits for what IR and whiskers sense
        cmd = self.layers.step()["move"]
        if cmd is not None and self.refused(int(cmd), (x, y, th)):
            cmd = self.layers.step()["move"]          # the guard reflex now holds the actuator
        trace = self.layers.trace("move")
        _since, _layer, module = trace.current
        if module != self.holder:
            self.holder = module
            self.takeovers[module] = self.takeovers.get(module, 0) + 1
        for name, m in self.layers.modules.items():   # every manoeuvre started, held or still suppressed by a
            plan = getattr(m, "plan", None)           # stronger one: its window (5.2 latency metric)
            if m.layer in (REFLEXES, AVOIDANCE) and plan is not None and plan is not self.escape_plans.get(name):
                self.escape_plans[name] = plan
                self.hw.note("escape", start=plan.started, end=plan.started + sum(d for d, _v in plan.steps),
                             module=name)
        if self.doubt and self.sent is not None and self.pending is None and not self.requested:
            self.doubt = False             # seed 3.2.2: the MOVE after a repeated grant may be lost too: send it again
            self.pending, self.sent_module = self.sent
            self.requested = True
            self.slave_send(ADDRESS_OF["MCP"], M.XmitReq())
        if cmd is not None:
            self.want(int(cmd), module)

    def refused(self, cmd: int, pose: tuple[float, float, float]) -> bool:
        """seed 5.1.2: the motion check. A command that would bring the body outline into the guard margin of
        an echo remembered at the dead-reckoned pose is refused; the guard reflex gets the safe alternative."""
        pts = body_frame(tuple(e.point() for e in self.echoes), pose)
        if closing_in(pts, cmd, self.tuning) == 0.0:
            return False
        fresh = self.now - self.touch_at <= T.NP3_TOUCH_FRESH_S
        self.bump("veto", safe_instead(pts, cmd, self.tuning, self.touch_side if fresh else 0.0))
        return True

    def plan_goal(self, now: float) -> None:
        """seed 3.3.2 / 5.2: the task layer's next goal, every NP3_EXPLORE_PLAN_S or when it is reached.

        First choice: the heading whose ray through the map runs longest over cells not passed yet before a
        mapped obstacle, with a goal along it (short of the obstacle; not a heading the robot was just kept
        from, not_approached). When no heading is open (boxed in by
        walls, pits, refused slopes) or a route is being followed, a route over the topological map to the
        nearest frontier (free space bordering unknown space, at least NP3_PLAN_MIN_PATH_M away), waypoint
        by waypoint; it is planned again (the map has changed) every NP3_EXPLORE_PLAN_S.
        (Measured, issue 17: frontier routes as the first choice covered less of the explore room, 0.36-0.40
        against 0.45-0.50 on seeds 1-3, so they are the way out, not the rule; seeking a light the samples do
        not show, they are the rule: the light is where the robot has not been.)
        """
        x, y, th = self.odo.pose
        route = self.map.plan
        if route and now < self.next_plan:
            if math.dist(route[0], (x, y)) < T.NP3_GOAL_REACHED_M:
                route.pop(0)
            if route:
                self.goal = route[0]
                self.layers.sense(goal=self.goal)
                return
        if now < self.planned_at + T.NP3_PLAN_CHANGED_S:
            return                                 # a goal reached at once (a short ray): not a rebuild every tick
        self.planned_at = now
        self.next_plan = now + T.NP3_EXPLORE_PLAN_S
        self.map.plan = []
        self.not_approached(x, y)
        ring = self.ringed(x, y)
        if ring is not None:                       # pits all round: the way out over the map, through its gap
            self.goal = self.route_out(x, y, ring)
            if self.goal is not None:
                self.chose(now, "out", 0.0)
                return
        if self.cfg.task == "seek_light":          # searching for a light it cannot see: the nearest unknown
            # the widest opening onto the unknown first, round walls by the map (a lamp behind a wall)
            self.goal = self.route_to_frontier(x, y, now, T.NP3_SEEK_FRONTIER_WEIGHT_M)
            if self.goal is not None:
                self.chose(now, "frontier", 0.0)
                return
        best = self.open_heading(x, y, th)
        if best is not None:
            length = min(best.free_m - T.NP3_EXPLORE_MARGIN_M, T.NP3_EXPLORE_GOAL_M)
            self.goal = (x + length * math.cos(best.heading), y + length * math.sin(best.heading))
            self.map.plan = [self.goal]            # the picture shows it (topomap.png)
            self.heading_plan = HeadingPlan(x, y, best.heading, self.goal, length, self.fights())
            self.chose(now, "heading", best.fresh_m)
        else:
            self.goal = self.route_to_frontier(x, y, now)
            self.chose(now, "frontier" if self.goal is not None else "none", 0.0)

    def fights(self) -> int:
        """How often a layer above the task (avoidance, reflexes) has taken the actuator so far."""
        return sum(n for module, n in self.takeovers.items() if module != "task")

    def not_approached(self, x: float, y: float) -> None:
        """The last heading goal, if the robot came no NP3_PLAN_PROGRESS_M nearer it while a stronger layer
        took the actuator, is blocked where the map shows it open (a surface mapped off its place, a thin end
        the sonar misses): that heading is not chosen again near here. Else the same free ray was chosen
        every plan and avoidance turned the robot back each time, 30-40 s on the spot (maze_far_room seed 9,
        issue 17)."""
        hp, self.heading_plan = self.heading_plan, None
        if hp is None or self.fights() == hp.fights:
            return
        if math.dist(hp.goal, (x, y)) > max(hp.left_m - T.NP3_PLAN_PROGRESS_M, T.NP3_GOAL_REACHED_M):
            self.blocked.append(hp._replace(x=x, y=y))

    def chose(self, now: float, kind: str, fresh_m: float) -> None:
        """Hand the goal to the task layer and log the plan."""
        x, y, _ = self.odo.pose
        self.plans.append(PlanRecord(now, x, y, kind, fresh_m, tuple(self.map.plan)))
        self.layers.sense(goal=self.goal)

    def open_heading(self, x: float, y: float, th: float) -> OpenHeading | None:
        """The heading whose ray through the map runs longest over cells not passed yet before a mapped
        obstacle (turns cost a little, long free rays count a little); None when no ray is free past
        NP3_EXPLORE_MARGIN_M."""
        g = self.map.grid
        best: OpenHeading | None = None
        for k in range(T.NP3_EXPLORE_HEADINGS):
            turn = (2 * math.pi * k / T.NP3_EXPLORE_HEADINGS + math.pi) % (2 * math.pi) - math.pi
            h = th + turn
            if any(math.dist((b.x, b.y), (x, y)) < T.NP3_EXPLORE_BLOCKED_M
                   and abs(wrap_angle(h - b.heading)) < math.radians(T.NP3_EXPLORE_BLOCKED_DEG) for b in self.blocked):
                continue
            free = fresh = 0.0
            for cell in ray_cells(x, y, h, T.NP3_EXPLORE_REACH_M, g.res, g.x0, g.y0):
                if not g.inside(*cell) or g.state(*cell) == OCCUPIED:
                    break
                free = math.dist((x, y), g.centre(*cell))
                fresh += g.res * (cell not in self.visited)
            score = fresh + 0.2 * free - 0.3 * abs(turn)
            if free > T.NP3_EXPLORE_MARGIN_M and (best is None or score > best.score):
                best = OpenHeading(score, h, free, fresh)
        return best

    def route_to_frontier(self, x: float, y: float, now: float, size_weight: float = 0.0) \
            -> tuple[float, float] | None:
        """seed 3.3.2: a route over the rebuilt topological map to the frontier kept as the target
        (FrontierTarget: the nearest, a cell of it worth `size_weight` m of path, until explored, refuted or
        not approached); its first waypoint."""
        self.map.rebuild()
        self.map.plan = self.frontier_target.route(self.map, x, y, now, T.NP3_GOAL_REACHED_M,
                                                   min_size=T.NP3_PLAN_MIN_FRONTIER,
                                                   min_path_m=T.NP3_PLAN_MIN_PATH_M, size_weight=size_weight)
        if not self.map.plan:
            return None
        self.routes_planned += 1
        return self.map.plan[0]

    def map_changed(self) -> None:
        """seed 3.3.2: a barrier joined the map: plan again within NP3_PLAN_CHANGED_S (not at every record of a
        slope the body stands on: one rebuild per that time at most)."""
        self.next_plan = min(self.next_plan, self.now + T.NP3_PLAN_CHANGED_S)

    def mark_visited(self, x: float, y: float) -> None:
        """The map cells within NP3_EXPLORE_SEEN_M of the dead-reckoned path (what exploring has covered)."""
        g = self.map.grid
        ci, cj = g.cell(x, y)
        if (ci, cj) == self.last_cell:
            return
        self.last_cell = (ci, cj)
        n = int(T.NP3_EXPLORE_SEEN_M / g.res)
        self.visited.update((ci + di, cj + dj) for di in range(-n, n + 1) for dj in range(-n, n + 1)
                            if di * di + dj * dj <= n * n)

    # --- moving: XMIT_REQ -> XMIT_GRANT -> MOVE (seed 3.2.2) -----------------------------------
    def want(self, mov_cmd: int, module: str) -> None:
        """Send a MOVE when the command changes or another module takes over (it reacts, 5.2)."""
        if self.sent == (mov_cmd, module) and self.pending is None:
            return
        if self.sent is not None and self.sent[0] == mov_cmd and self.pending is None and module == "task":
            self.sent = (mov_cmd, module)         # back to the task with the same command: nothing to send
            return
        self.pending = mov_cmd
        self.sent_module = module
        if not self.requested:
            self.requested = True
            self.slave_send(ADDRESS_OF["MCP"], M.XmitReq())

    def on_xmit_grant(self, src: int, msg: M.XmitGrant) -> None:
        self.requested = False
        if self.pending is None:
            if self.sent is not None:      # a repeated grant: our record did not get through
                self.send(src, M.Move(mov_cmd=self.sent[0], param=0))
                self.doubt = True          # it may be lost again: ask for the bus once more next period
            return
        mov, self.pending = self.pending, None
        self.sent = (mov, self.sent_module)
        self.moves_sent += 1
        self.odo.command(self.now, mov)
        self.pinned.command(self.now, mov)
        self.send(src, M.Move(mov_cmd=mov, param=0))

    # --- sensing: DATA records only ----------------------------------------------------------------
    def on_data(self, src: int, msg: M.Data) -> None:
        if msg.address not in NODES:
            return
        self.records += 1
        role, kind, ch, v = NODES[msg.address].role, msg.kind, msg.channel, msg.value
        measured_at = self.now - RECORD_AGE.phys(msg.age)          # issue 17: when the source measured it
        self.heard.add(role)
        urgent = True
        if role == "MMC" and kind == _STATUS:
            self.mmc_status(ch, v)
        elif kind == _STATUS and role in ("IRRC", "USRC"):
            self.range_status(role, v)
        elif role == "TPSC" and v:
            left = bool(v & (TpscContact.OBJ_LEFT | TpscContact.OBJ_BOTH))
            right = bool(v & (TpscContact.OBJ_RIGHT | TpscContact.OBJ_BOTH))
            feeler = T.NP3_WHISKER_ARMS if left else mirrored(T.NP3_WHISKER_ARMS)
            side_wire = max(feeler, key=lambda arm: abs(arm[-1].y))     # the wire reaching furthest out
            alongside = left != right and self.ir == [None, None, None] and self.wall_alongside(side_wire)
            self.bump("whisker", left, right, self.now, alongside)      # seed 3.2.12
            if left != right:                                           # one feeler: the side the surface is on
                self.touch_at, self.touch_side = self.now, 1.0 if left else -1.0
            self.stopped_by_reflex(msg.address)
            for arms, hit in ((T.NP3_WHISKER_ARMS, left), (mirrored(T.NP3_WHISKER_ARMS), right)):
                # the touch: anywhere on the feeler's wires, so points near each root, middle and tip; a wall
                # alongside touches the side wire's tip (the point furthest out), nothing in the legs' way (D18)
                for arm in ((side_wire,) if alongside else arms) if hit else ():
                    for pt in (along(arm, k) for k in ((1.0,) if alongside else (0.2, 0.5, 0.85))):
                        self.echo(pt.x, pt.y, 0.0, 0.0)
        elif role == "IRRC" and 0 <= ch < 3:                            # seed 3.2.13: beam 0 left, 1 centre, 2 right
            self.ir[ch] = None if v >= _Q["IRRC"].hi else decode(role, v) / 100
            if self.ir[ch] is not None:
                self.echo(T.NP3_BODY_FRONT_M, 0.0, (1 - ch) * T.NP3_IR_BEAM_DEG, self.ir[ch], at=measured_at)
            self.layers.sense(ir=tuple(self.ir))
        elif role == "ISC" and ch in (0, 1):                            # seed 3.2.14: axis 0 / 1
            self.tilt[ch] = decode(role, v)
            self.layers.sense(tilt=tuple(self.tilt))
            if steepness_deg(self.tilt) > self.tuning.tilt_limit_deg:
                self.refuse_slope()
        elif role == "PSC":                                             # seed 3.2.17: under-voltage stops the robot
            if kind == _ALARM:        # the PSC judges under-voltage (SET_ALARM); a VALUE is a measurement under
                self.battery_low = True                                 # load, and the MCP beeps on the ALARM only
                self.layers.sense(battery_low=True)
        elif role == "LSC":
            self.light(decode(role, v))
            urgent = False
        elif role == "USRC":
            self.sonar(ch, v, measured_at)
            urgent = False
        elif role == "APU_SDF" and kind == _VALUE:                      # seed 3.2.7: sound direction, body frame
            self.bump("sound", ch)
        else:
            urgent = False
        if urgent and self.running:
            self.tick()                                                 # 5.2: react now, not next period

    def wall_alongside(self, wire: FeelerArm) -> bool:
        """A single-switch touch (IR beams clear) is a wall alongside that met this side wire, not the lane
        wire, when the sonar's echo memory shows a surface beside the body on its side: at most
        NP3_CONTACT_WALL_BEYOND_M further out than the wire's tip and within NP3_CONTACT_WALL_ALONG_M of it
        along the axis (D18, CHOICE: the switch does not say which wire; a wall along the way meets the side
        wire's tip first, the feelers' point furthest out). Why: the lane wire's points read as a blocked way
        ahead, and the 60 deg guess turned the body from one wall of corridor_narrow (0.5 m wide, the side wire
        reaching 17.7 cm beside the axis) to face the other. Only sonar echoes count (a touch's own points lie
        on the wires), and the posts the feelers are for are lower than the sonar head: a post met leaves all
        the wires' points. The band is wide because the memory's walls are where the dead-reckoned
        heading put them (10-25 deg off in corridor_narrow; 5 cm round the wire found 14 of 32 touches on seeds 3
        and 12, and 7 of seeds 1-20 passed)."""
        pts = body_frame(tuple(e.point() for e in self.echoes if e.sonar), self.pose_at(None))
        tip = wire[-1]
        side = 1.0 if tip.y > 0 else -1.0
        return any(self.tuning.body_half_width_m < by * side < abs(tip.y) + T.NP3_CONTACT_WALL_BEYOND_M
                   and abs(bx - tip.x) < T.NP3_CONTACT_WALL_ALONG_M for bx, by, _s, _a in pts)

    def stopped_by_reflex(self, source: int) -> None:
        """spec reflexes (seed 5.2): the MCP stopped the legs when this record passed it; what we sent last no
        longer holds, so the network's next command goes out even if it equals that one."""
        r = self.net.reflex_from(source)
        if r is None or r.to != ADDRESS_OF["MMC"]:
            return
        self.stopped_by_mmc(int(MovCmd[r.command]))

    def stopped_by_mmc(self, cmd: int) -> None:
        """The MMC walks `cmd` now though the NP3 did not send it (a reflex, or its own stop at a pit): the
        reckoning walks it too (no motion counted that the legs did not make), and the network's next command
        goes out even if it equals what we sent last."""
        self.odo.command(self.now, cmd)
        self.pinned.command(self.now, cmd)
        self.sent = (cmd, "reflex")

    def bump(self, register: str, *data: Any) -> None:
        self.seq[register] += 1
        self.layers.sense(**{register: (self.seq[register], *data) if data else self.seq[register]})

    def mmc_status(self, leg: int, error: int) -> None:
        """MMC STATUS_ACK error as the MCP relays it: a pit or a blocked leg starts a reflex once per report."""
        if (error, leg) != self.mmc_error:
            if error == _NO_GROUND:                  # seed 1.2.2: where the foot found no ground, in the body frame
                self.stopped_by_mmc(_STOP)           # ... the MMC stopped there at once (mmc.py, seed 1.2.2)
                fx, fy = self.geo.neutral_foot(leg) if leg in self.geo.legs else (self.geo.hip_x[0], 0.0)
                self.echo(fx, fy, 0.0, 0.0)          # the edge joins the local memory (the motion check) ...
                self.mark_pit(fx, fy)                # ... and the map: the pit is part of it (3.3.2)
                self.map_changed()
                self.bump("pit", fx, fy)
            elif error == _BLOCKED:
                self.bump("leg_blocked", self.geo.side(leg) if leg in self.geo.legs else 0.0)
            elif error in _LEG_LOST and leg in self.geo.legs:
                self.odo.leg_lost(self.now, leg)     # seed 6.3: the MMC walks on five from now on
        self.mmc_error = (error, leg)
        if isinstance(self.odo, GaitReckoning):     # CHOICE: no motion counted while a foot has no ground
            self.odo.advance(self.now)              # (tuning NP3_DR_FOOTLESS_GRIP: the body hardly turns then)
            self.odo.footless = error == _NO_GROUND

    def mark_pit(self, fx: float, fy: float) -> None:
        """seed 1.2.2 / 3.3.2: a foot found no ground at (fx, fy) (body frame): the pit's edge joins the map.

        CHOICE: as a stretch NP3_PIT_EDGE_DEEP_M deep from the foot on, across the way the foot went (ahead of a
        front foot, behind a rear one, beside a middle one): a front or rear foot's from the body's axis out to
        NP3_PIT_EDGE_OUT_M beyond the foot (the other side's foot stands on ground, so the edge does not cross
        the axis), a middle foot's NP3_PIT_EDGE_ALONG_M either way along the body (its neighbours on that side
        stand on ground). One cell per report left a ring of pits as scattered dots the sonar's free space
        lay between (the sonar sees no hole), so no route over the map went round it (pit_ring, issue 17).
        The edge's true direction is not known: one met diagonally, or beside the body in a gap, is marked
        square to the body, and a stretch centred on the foot closed pit_ring's gap on the map from both sides.
        """
        g = self.map.grid
        step = g.res / 2
        if abs(fx) >= 0.05:                     # a front or rear foot: the edge ahead of it (behind it)
            nx, ny = math.copysign(1.0, fx), 0.0
            out = fy + math.copysign(T.NP3_PIT_EDGE_OUT_M, fy) if fy else T.NP3_PIT_EDGE_OUT_M
            lo, hi = sorted((0.0 if fy else -out, out))
            across = [(fx, lo + k * step) for k in range(int(round((hi - lo) / step)) + 1)]
        else:                                   # a middle foot: the edge beside it
            nx, ny = 0.0, math.copysign(1.0, fy)
            n = int(round(T.NP3_PIT_EDGE_ALONG_M / step))
            across = [(fx + m * step, fy) for m in range(-n, n + 1)]
        self.pits_met += 1
        for depth in (d * step for d in range(int(round(T.NP3_PIT_EDGE_DEEP_M / step)) + 1)):
            for bx, by in across:
                wx, wy = self.at_body(bx + depth * nx, by + depth * ny)
                g.mark_barrier(wx, wy)
                self.pit_cells.setdefault(g.cell(wx, wy), (wx, wy))

    def ringed(self, x: float, y: float) -> RingOut | None:
        """seed 3.3.2: while the pits found hem the robot in, the ring they lie on (the middle of its path till
        then, and NP3_RING_OUT_M beyond the farthest pit cell found near that); None when they do not hem it
        in, or once it stands beyond that.

        CHOICE: hemmed in = the feet found NP3_RING_PITS pit edges (the way the robot chose ended at a pit,
        and the next way again): it stops following the open rays the sonar sees over the holes and plans a
        way out. Measured, pit_ring seeds 1-10 at 120 s: with two edges facing 90 deg apart asked for, the
        robot stood in the gap at 41 s (seed 5) and was sent back in by an open ray; with any two, 8 of 10
        left the ring. The ring's middle is the mean of the path walked till then: the robot walked only
        where the ground held, inside the ring (where it stood when it found the second pit was no middle:
        in the gap, with a pit either side, the ring's inside lay beyond those two)."""
        if self.ring is None and self.pits_met >= T.NP3_RING_PITS:
            path = self.map.path
            self.ring = RingOut(sum(p[0] for p in path) / len(path), sum(p[1] for p in path) / len(path), 0.0)
        if self.ring is None:
            return None
        c = (self.ring.x, self.ring.y)
        far = max((d for p in self.pit_cells.values() if (d := math.dist(p, c)) <= T.NP3_RING_NEAR_M), default=0.0)
        self.ring = self.ring._replace(radius=far + T.NP3_RING_OUT_M)
        if math.dist((x, y), c) > self.ring.radius:        # out: explore on; pits met from here on count anew
            self.ring, self.rings_left = None, self.rings_left + 1
            self.pits_met = 0
        return self.ring

    def route_out(self, x: float, y: float, ring: RingOut) -> tuple[float, float] | None:
        """seed 3.3.2: a route over the rebuilt map out of the ring of pits (TopoMap.route_out); its first waypoint."""
        self.map.rebuild()
        route = self.map.route_out((x, y), (ring.x, ring.y), ring.radius, list(self.pit_cells.values()),
                                   T.NP3_RING_WARY_M, T.NP3_RING_WARY_COST)
        while route and len(route) > 1 and math.dist(route[0], (x, y)) < T.NP3_GOAL_REACHED_M:
            route.pop(0)
        self.map.plan = route or []
        if not route:
            return None
        self.routes_planned += 1
        self.routes_out += 1
        return route[0]

    def range_status(self, role: str, status: int) -> None:
        bad = status in _IR_BAD
        if role == "IRRC":                       # seed 6.2: IR not trustworthy -> stop
            self.ir_fault = bad
            self.layers.sense(ir_fault=bad)
        else:                                    # seed 6.2: US not trustworthy -> its data are ignored
            self.sonar_ignored = bad
            if bad:
                self.sonar_ahead = None

    def pose_at(self, t: float | None) -> tuple[float, float, float]:
        """The dead-reckoned pose now (t None) or at the earlier time t (a record's measurement, issue 17)."""
        self.odo.advance(self.now)
        return self.odo.pose if t is None else self.odo.pose_at(t)

    def at_body(self, bx: float, by: float, at: float | None = None) -> tuple[float, float]:
        """A body-frame point (x forward, y left) in the world frame of the dead-reckoned pose now (or at `at`)."""
        x, y, th = self.pose_at(at)
        return x + bx * math.cos(th) - by * math.sin(th), y + bx * math.sin(th) + by * math.cos(th)

    def echo(self, bx: float, by: float, rel_deg: float, d: float, cone_deg: float = 0.0,
             at: float | None = None) -> None:
        """An obstacle point seen from (bx, by) in the body frame, d m away at rel_deg, kept in world (DR) terms
        with the angle it was seen at: the local memory the tasks steer by. `at`: when it was measured; the
        point is placed from the pose the robot had then (issue 17: a sonar echo reaches the NP3 late)."""
        ox, oy = self.at_body(bx, by, at)
        a = self.pose_at(at)[2] + math.radians(rel_deg)
        arc = d * math.sin(math.radians(cone_deg / 2))        # the echo may come from anywhere across the cone
        self.echoes.append(Echo(self.now, ox + d * math.cos(a), oy + d * math.sin(a), rel_deg, arc))

    def refuse_slope(self) -> None:
        """A too steep slope is a boundary whatever the heading (3.2.14): the ground uphill of the body joins
        the local memory (the motion check keeps the body off it) and the map, like a pit's edge."""
        ux, uy = uphill(self.tilt)
        n = math.hypot(ux, uy)
        for ahead in (0.2, 0.3):
            bx, by = ahead * ux / n, ahead * uy / n
            self.echo(bx, by, 0.0, 0.0)
            self.map.grid.mark_barrier(*self.at_body(bx, by))
        self.map_changed()

    def light(self, lux: float) -> None:
        self.lux.append(lux)
        x, y, _ = self.odo.pose
        self.seq["light"] += 1
        self.layers.sense(light=(self.seq["light"], x, y, math.log10(max(lux, 1e-3))))

    def sonar(self, head_deg: int, raw: int, pinged_at: float) -> None:
        """seed 3.3.2: an echo (channel = head angle, body frame) into the map at the dead-reckoned pose of its
        ping (issue 17: placed at the pose of arrival, a turning robot put walls into its own path)."""
        if self.sonar_ignored:
            return
        d = None if raw >= _Q["USRC"].hi else decode("USRC", raw)
        x, y, th = self.pose_at(pinged_at)
        rel = (head_deg + 180) % 360 - 180
        if abs(rel) <= T.NP3_SONAR_AHEAD_DEG and d is not None:
            self.sonar_ahead = (pinged_at, d)
        if self.pinned.heard(rel, d, pinged_at, (x, y),
                             self.pinned.alongside(body_frame(tuple(e.point() for e in self.echoes), self.odo.pose))):
            self.bump("pinned")
        self.sonar_memory(Ping(self.now, x, y, th + math.radians(rel), _Q["USRC"].phys(_Q["USRC"].hi) if d is None
                               else d), rel)
        half, n = T.NP3_SONAR_BEAM_DEG / 2, 5
        if self.cfg.task in _PLANNING and d is not None and T.NP3_MATCH_RANGE_M[0] <= d <= T.NP3_MATCH_RANGE_M[1]:
            off = heading_offset(self.map.grid, x, y, th + math.radians(head_deg), d, T.NP3_SONAR_BEAM_DEG, n,
                                 T.NP3_MATCH_SEARCH_DEG, T.NP3_MATCH_TOL_M, T.NP3_MATCH_WIDTH_DEG)
            if off is not None:
                self.correct_heading(self.heading_votes.add(off))
                x, y, th = self.pose_at(pinged_at)      # the ping's pose in the corrected frame (history turned too)
        cone = [Reading(x, y, math.degrees(th), head_deg - half + 2 * half * k / (n - 1), d) for k in range(n)]
        self.map.add(cone)

    def sonar_memory(self, ping: Ping, rel_deg: float) -> None:
        """Issue 17: a sonar echo is the nearest reflector anywhere across the beam, so it joins the local memory
        as points spread over the cone, each with how far across the beam the reflector may lie from it (to the
        cone's far edge: clear_ahead counts only echoes surely in the way; a point at the cone's edge is not the
        centre of the arc, and giving it the half-width made a wall alongside seen 15 deg off the axis a corner
        ahead, wall_follow); what a ping shows free (nearer than its echo) clears the points of other pings
        there. In a corridor the cone's inner edge lies inside the legs' way, and only the pings from further
        on, whose cones pass over that spot, show it free."""
        while self.pings and ping.t - self.pings[0].t > T.NP3_SONAR_CARVE_S:
            self.pings.popleft()
        if any(e.sonar and ping.clears(e.x, e.y) for e in self.echoes):
            self.echoes = deque(e for e in self.echoes if not (e.sonar and ping.clears(e.x, e.y)))
        if ping.reach < T.NP3_ECHO_NEAR_M:
            n = T.NP3_SONAR_CONE_POINTS
            half = math.radians(T.NP3_SONAR_BEAM_DEG / 2)
            for k in range(n):
                off = -half + 2 * half * k / (n - 1)
                px, py = ping.x + ping.reach * math.cos(ping.bearing + off), ping.y + ping.reach * math.sin(ping.bearing + off)
                arc = ping.reach * (math.sin(half) + abs(math.sin(off)))   # the reflector: anywhere up to the far edge
                if not any(p.clears(px, py) for p in self.pings):
                    self.echoes.append(Echo(self.now, px, py, rel_deg + math.degrees(off), arc, sonar=True))
        self.pings.append(ping)

    def correct_heading(self, turn: float) -> None:
        """seed 3.3.2: the map says the dead-reckoned heading is `turn` rad off: turn it, and with it about the
        robot the pose history, the echoes of the local memory and the pings' free space (all placed with the old
        heading), so that they stay where the corrected pose sees them."""
        if not turn:
            return
        self.odo.advance(self.now)
        x, y, _ = self.odo.pose
        self.odo.turn_heading(turn)
        self.echoes = deque(turned_about(e, x, y, turn) for e in self.echoes)
        self.pings = deque(turned_about(p, x, y, turn) for p in self.pings)
        self.heading_fixed += turn

    # --- debug port --------------------------------------------------------------------------------
    def debug_metrics(self) -> Np3Debug:
        """Which layer held the MMC and for how long (docs/decisions.md D8), reflex take-overs, map and light figures."""
        if "move" not in self.layers.traces:
            return {"control": {}, "switches": 0, "moves_sent": 0}
        trace = self.layers.trace("move")
        x, y, th = self.odo.pose
        self.map.rebuild()
        return {
            "control": {k: round(v, 2) for k, v in trace.summary(self.now).items()},
            "switches": trace.switches(self.now),
            "takeovers": dict(sorted(self.takeovers.items())),
            "moves_sent": self.moves_sent,
            "records": self.records,
            "pose": [round(x, 3), round(y, 3), round(math.degrees(th), 1)],
            "battery_low": self.battery_low,
            "ir_fault": self.ir_fault,
            "sonar_ignored": self.sonar_ignored,
            "map": {"places": len(self.map.places), "edges": len(self.map.edges), "routes": self.routes_planned,
                    "routes_out": self.routes_out, "rings_left": self.rings_left, "pit_cells": len(self.pit_cells),
                    "seen_m2": round(sum(self.map.grid.seen) * self.map.grid.res ** 2, 2),
                    "heading_fixed_deg": round(math.degrees(self.heading_fixed), 1)},
            "light": {"first_lux": round(self.lux[0], 1), "last_lux": round(self.lux[-1], 1),
                      "ratio": round(self.lux[-1] / self.lux[0], 3)} if self.lux else {},
        }

    def write_artifacts(self, out_dir: Path) -> None:
        """control.tsv (the control trace), wiring.txt (the declared network), topomap.png and plans.tsv (seed
        3.3.2: the map with the pits found, the routes out of a ring of them and the plan followed at the end,
        and every plan made)."""
        out = Path(out_dir)
        rows = ["start_s\tend_s\tlayer\tmodule"]
        if "move" in self.layers.traces:
            rows += [f"{iv.start:.3f}\t{iv.end:.3f}\t{iv.layer}\t{iv.module}"
                     for iv in self.layers.trace("move").intervals(self.now)]
        (out / "control.tsv").write_text("\n".join(rows) + "\n")
        (out / "wiring.txt").write_text(self.layers.wiring_table() + "\n")
        self.map.rebuild()
        task = self.layers.modules["task"]
        # seeking a light the samples show, the task climbs its gradient and the map's plan is not followed
        following = self.cfg.task == "seek_light" and isinstance(task, TaskModule) and not task.dark()
        self.map.save_png(out / "topomap.png", given_up=self.frontier_target.given_up,
                          plan=[] if following else None, pits=self.pit_cells.values(),
                          routes=[((p.x, p.y), *p.route) for p in self.plans if p.kind == "out"])
        plans = ["t_s\tx_m\ty_m\tkind\tfresh_m\troute"]
        plans += [f"{p.t:.2f}\t{p.x:.2f}\t{p.y:.2f}\t{p.kind}\t{p.fresh_m:.2f}\t"
                  + " ".join(f"{wx:.2f},{wy:.2f}" for wx, wy in p.route) for p in self.plans]
        (out / "plans.tsv").write_text("\n".join(plans) + "\n")
