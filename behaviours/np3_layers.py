"""The NP3's subsumption network (docs/decisions.md D8, seed 5.1-5.2, 6): its layers, tasks and wiring.

Layers, lowest (strongest) first, as the issue orders them:
  - reflexes: contact (whisker or IR very close), pit (MMC NO_GROUND), dangerous
    tilt, low battery, blocked leg, unreliable or failed IR;
  - avoidance: an obstacle ahead seen by the IR beams or the sonar;
  - task: the current task (forward, explore, wall_follow, seek_light,
    avoid_light, idle), with a sound-orienting module on top of it.

Every module reads registers the NP3 node fills from the DATA records it
receives (behaviours.np3); the wiring is declared data: the task drives the
actuator "move" (the Mov_Cmd for the MMC, 3.2.3) on an ordinary wire, every
other module suppresses that input with a time constant. Pure logic: the
clock is injected and the numbers come from behaviours.tuning.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable, Mapping, NamedTuple

from arachnae_proto.enums import MovCmd
from arachnae_proto.messages import XmitDataLsc

from behaviours import tuning as T
from behaviours.geometry import DEFAULT_GEOMETRY
from behaviours.subsumption import Clock, Network, Outputs, Plan, ReflexModule
from behaviours.units import XMIT_DATA_OF, quantizer

STOP, FORWARD, BACKWARD = MovCmd.STOP, MovCmd.FORWARD, MovCmd.BACKWARD
LEFT, RIGHT = MovCmd.TURN_LEFT, MovCmd.TURN_RIGHT
SIDE_LEFT, SIDE_RIGHT = MovCmd.SIDESTEP_LEFT, MovCmd.SIDESTEP_RIGHT

REFLEXES, AVOIDANCE, TASK = "reflexes", "avoidance", "task"
TASKS = ("forward", "explore", "wall_follow", "seek_light", "avoid_light", "idle")

Steps = list[tuple[float, Any]]
Trigger = Callable[[Mapping[str, Any], float], "Steps | None"]

# Sensor registers of the network (set by the node with net.sense(...)):
#   whisker WhiskerEvent         a TPSC contact event      ir (left, centre, right) m, None = nothing in range
#   ir_fault bool                IRRC unreliable / failed   pit int                 count of MMC NO_GROUND reports
#   tilt (lon, transverse) deg   ISC                        battery_low bool        latched PSC alarm / low value
#   leg_blocked (seq, side)      blocked report, +1 left    sonar_ahead_m m | None  a fresh sonar echo ahead
#   light (seq, x, y, log10 lux) LSC sample at the pose     pose (x, y, heading rad) dead reckoning
#   goal (x, y) | None           explore: frontier target   sound (seq, direction deg) APU/SDF event
#   echoes ((x, y, seen_deg, arc_m), ...) obstacle points of the last seconds (sonar, IR, whiskers) at the DR
#                                pose, seen at body angle seen_deg, somewhere within arc_m across the beam
#   veto (seq, command)          the node's motion check refused the command the network chose: do this instead
#   mapped ((x, y, 0, arc_m), ...) occupied cells of the topological map round the DR pose (3.3.2): what the
#                                echo memory has let go of (a block walked along for longer than it keeps echoes)
#   pinned int                   count of PinnedCheck's findings: the body held by something no sensor sees
_BRIGHTNESS = next(f.conv for f in XmitDataLsc.FIELDS if f.name == "brightness")
# seed 3.2.16: one step of the LSC's logarithmic brightness code in log10 lux (1/64 decade), from the spec
LSC_STEP_LOG = math.log10(_BRIGHTNESS.to_phys(_BRIGHTNESS.hi) / _BRIGHTNESS.to_phys(_BRIGHTNESS.lo)) \
    / (_BRIGHTNESS.hi - _BRIGHTNESS.lo)

SENSORS = ("whisker", "ir", "ir_fault", "pit", "tilt", "battery_low", "leg_blocked", "sonar_ahead_m", "light",
           "pose", "goal", "sound", "echoes", "veto", "mapped", "pinned")


_IRRC = quantizer(XMIT_DATA_OF["IRRC"], "center")
IR_RANGE_M = _IRRC.phys(_IRRC.hi) / 100     # spec: the IRRC's reach (cm); its top code means nothing in range


@dataclass(frozen=True)
class Tuning:
    """The network's thresholds and time constants (CHOICE; defaults from behaviours.tuning)."""

    reflex_hold_s: float = T.NP3_REFLEX_HOLD_S
    avoid_hold_s: float = T.NP3_AVOID_HOLD_S
    contact_back_s: float = T.NP3_CONTACT_BACK_S
    contact_min_turn_deg: float = T.NP3_CONTACT_MIN_TURN_DEG
    contact_clear_deg: float = T.NP3_CONTACT_CLEAR_DEG
    contact_ahead_deg: float = T.NP3_CONTACT_AHEAD_DEG
    contact_whisker_normal_deg: float = T.NP3_CONTACT_WHISKER_NORMAL_DEG
    contact_corner_m: float = T.NP3_CONTACT_CORNER_M
    contact_corner_normal_deg: float = T.NP3_CONTACT_CORNER_NORMAL_DEG
    contact_near_m: float = T.NP3_CONTACT_NEAR_M
    contact_alongside_s: float = T.NP3_CONTACT_ALONGSIDE_S
    contact_alongside_min_deg: float = T.NP3_CONTACT_ALONGSIDE_MIN_DEG
    contact_wall_reach_m: float = T.NP3_CONTACT_WALL_REACH_M
    ir_range_m: float = IR_RANGE_M
    ir_beam_deg: float = T.NP3_IR_BEAM_DEG
    ir_contact_m: float = T.NP3_IR_CONTACT_M
    avoid_centre_m: float = T.NP3_AVOID_CENTRE_M
    avoid_side_m: float = T.NP3_AVOID_SIDE_M
    avoid_sonar_m: float = T.NP3_AVOID_SONAR_M
    avoid_turn_s: float = T.NP3_AVOID_TURN_S
    avoid_keep_side_s: float = T.NP3_AVOID_KEEP_SIDE_S
    avoid_square_deg: float = T.NP3_AVOID_SQUARE_DEG
    pit_back_s: float = T.NP3_PIT_BACK_S
    pit_turn_s: float = T.NP3_PIT_TURN_S
    tilt_limit_deg: float = T.NP3_TILT_LIMIT_DEG
    tilt_back_s: float = T.NP3_TILT_BACK_S
    tilt_turn_s: float = T.NP3_TILT_TURN_S
    leg_blocked_hold_s: float = T.NP3_LEG_BLOCKED_HOLD_S
    leg_blocked_side_s: float = T.NP3_LEG_BLOCKED_SIDE_S
    avoid_echo_m: float = T.NP3_AVOID_ECHO_M
    avoid_half_width_m: float = T.NP3_AVOID_HALF_WIDTH_M
    sound_min_deg: float = T.NP3_SOUND_MIN_DEG
    wander_s: float = T.NP3_EXPLORE_WANDER_S
    wander_turn_s: float = T.NP3_EXPLORE_TURN_S
    goal_reached_m: float = T.NP3_GOAL_REACHED_M
    heading_tol_deg: float = T.NP3_HEADING_TOL_DEG
    wall_target_m: float = T.NP3_WALL_TARGET_M
    wall_deadband_m: float = T.NP3_WALL_DEADBAND_M
    wall_corner_m: float = T.NP3_WALL_CORNER_M
    wall_align_deg: float = T.NP3_WALL_ALIGN_DEG
    wall_lost_s: float = T.NP3_WALL_LOST_S
    side_speed_m_s: float = T.NP3_DR_SIDE_M_S
    light_samples: int = T.NP3_LIGHT_SAMPLES
    light_min_spread_m: float = T.NP3_LIGHT_MIN_SPREAD_M
    light_probe_s: float = T.NP3_LIGHT_PROBE_S
    light_clear_m: float = T.NP3_LIGHT_CLEAR_M
    light_weave_deg: float = T.NP3_LIGHT_WEAVE_DEG
    light_weave_s: float = T.NP3_LIGHT_WEAVE_S
    light_detour_step_deg: float = T.NP3_LIGHT_DETOUR_STEP_DEG
    light_detour_hold_s: float = T.NP3_LIGHT_DETOUR_HOLD_S
    light_flat_log: float = T.NP3_LIGHT_FLAT_STEPS * LSC_STEP_LOG
    turn_rate_deg_s: float = T.NP3_DR_TURN_DEG_S   # turn on the spot (measured; nominal 20 deg per 0.8 s)
    walk_speed_m_s: float = T.NP3_DR_SPEED_M_S
    body_half_length_m: float = T.NP3_BODY_FRONT_M
    body_half_width_m: float = DEFAULT_GEOMETRY.body_width / 2
    guard_margin_m: float = T.NP3_GUARD_MARGIN_M
    guard_horizon_s: float = T.NP3_GUARD_HORIZON_S
    guard_hold_s: float = T.NP3_GUARD_HOLD_S
    pinned_progress_m: float = T.NP3_PINNED_PROGRESS_M
    pinned_change: float = T.NP3_PINNED_CHANGE
    pinned_angles: int = T.NP3_PINNED_ANGLES
    pinned_range_m: tuple[float, float] = T.NP3_PINNED_RANGE_M
    pinned_window_s: float = T.NP3_PINNED_WINDOW_S
    pinned_beside_m: float = T.NP3_PINNED_BESIDE_M
    pinned_ref_s: float = T.NP3_PINNED_REF_S


def _seen(ir: Any) -> list[float | None]:
    return list(ir) if ir else [None, None, None]


class _Edge:
    """Remembers the last event number seen: a reflex starts once per new event, not while a flag stays set."""

    def __init__(self) -> None:
        self.last: Any = None

    def new(self, value: Any) -> bool:
        if value is None or value == self.last:
            return False
        fresh = self.last is not None or value not in (0, None)
        self.last = value
        return fresh


# --------------------------------------------------------------------------- level 0: reflexes
class Surface(NamedTuple):
    """One surface the contact sensors sense, in the body frame."""

    normal_rad: float      # direction from the body towards the surface (0 ahead, counter-clockwise positive)
    dist_m: float | None   # the body centre's distance to it along that direction, None when not measured


def ir_points(ir: Any, t: Tuning) -> list[tuple[float, float]]:
    """Body-frame points where the IR beams (seed 3.2.13: 0 and +-ir_beam_deg, mounted at the front) see something."""
    out = []
    for d, deg in zip(_seen(ir), (t.ir_beam_deg, 0.0, -t.ir_beam_deg)):
        if d is not None:
            a = math.radians(deg)
            out.append((t.body_half_length_m + d * math.cos(a), d * math.sin(a)))
    return out


def _line(pts: list[tuple[float, float]]) -> Surface:
    """The least-squares line through body-frame points (principal axis): its normal away from the body."""
    n = len(pts)
    mx, my = sum(p[0] for p in pts) / n, sum(p[1] for p in pts) / n
    sxx = sum((p[0] - mx) ** 2 for p in pts)
    syy = sum((p[1] - my) ** 2 for p in pts)
    sxy = sum((p[0] - mx) * (p[1] - my) for p in pts)
    along = 0.5 * math.atan2(2 * sxy, sxx - syy)
    nx, ny = -math.sin(along), math.cos(along)
    dist = nx * mx + ny * my
    if dist < 0:
        nx, ny, dist = -nx, -ny, -dist
    return Surface(math.atan2(ny, nx), dist)


def sensed_surfaces(ir: Any, side: float, beside: list[Point], t: Tuning) -> list[Surface]:
    """The surfaces touched, from the IR points: a line through two or three of them (its normal and distance),
    two lines meeting at the centre point when it lies behind the line through the side points by more than
    contact_corner_m, and an inside corner (walls facing the body at +-contact_corner_normal_deg from that line's
    normal) when both side beams see something and the centre beam, which would meet that line within its
    range, does not; one point: a surface facing the body at that point. Whiskers alone (the IR beams see
    nothing within their 10 cm): a surface ahead (both touched, side 0) or to the touched side (+1 left, -1
    right) facing the body at contact_whisker_normal_deg. Remembered echoes beside the body within
    contact_near_m of it add a surface each, facing the body at that point (a wall alongside: do not turn
    the body's corners into it)."""
    pts = ir_points(ir, t)
    out: list[Surface] = []
    seen = [d is not None for d in _seen(ir)]
    if len(pts) == 3:
        chord = _line([pts[0], pts[2]])
        cx, cy = pts[1]
        behind = cx * math.cos(chord.normal_rad) + cy * math.sin(chord.normal_rad) - (chord.dist_m or 0.0)
        out = [_line(pts[:2]), _line(pts[1:])] if behind > t.contact_corner_m else [_line(pts)]
    elif len(pts) == 2 and seen[0] and seen[2]:
        chord = _line(pts)
        a = math.radians(t.contact_corner_normal_deg)
        out = [chord]
        if chord.dist_m is not None and math.cos(chord.normal_rad) > 0 \
                and (chord.dist_m / math.cos(chord.normal_rad)) - t.body_half_length_m < t.ir_range_m:
            out = [chord._replace(normal_rad=chord.normal_rad + a), chord._replace(normal_rad=chord.normal_rad - a)]
    elif len(pts) == 2:
        out = [_line(pts)]
    elif pts:
        px, py = pts[0]
        out = [Surface(math.atan2(py, px), math.hypot(px, py))]
    else:
        out = [Surface(side * math.radians(t.contact_whisker_normal_deg), None)]
    return out + [Surface(math.atan2(by, bx), math.hypot(bx, by)) for bx, by, _s, _a in beside
                  if abs(bx) < t.body_half_length_m and body_gap(bx, by, t) < t.contact_near_m]


def turn_clear_deg(normals_deg: list[float], clear_deg: float, prefer: float) -> float:
    """The smallest turn on the spot (deg, counter-clockwise positive) after which every surface normal is at
    least 90 + clear_deg from the heading (each surface behind the robot's side); `prefer` (+1 left, -1 right)
    breaks a tie. 180 deg when no turn achieves it (surfaces all round: turn about and back out)."""
    need = 90.0 + clear_deg
    best: dict[float, float] = {}
    for sign in (1.0, -1.0):
        for k in range(0, 181):
            if all(abs((n - sign * k + 180.0) % 360.0 - 180.0) >= need for n in normals_deg):
                best[sign] = k
                break
    if not best:
        return 180.0 * prefer
    sign = min(best, key=lambda sg: (best[sg], sg != prefer))
    return sign * best[sign]


def contact_steps(surfaces: list[Surface], prefer: float, t: Tuning) -> Steps:
    """seed 5.1.2, 5.2: step away until turning on the spot cannot sweep the body's corners into a surface (back
    off from one ahead, never less than contact_back_s; sidestep from one alongside), then turn until every
    sensed surface is behind the robot's side by contact_clear_deg: the robot walks on away from them, not
    diagonally back into one."""
    steps: Steps = []
    sweep = math.hypot(t.body_half_length_m, t.body_half_width_m) + t.guard_margin_m
    ahead_rad = math.radians(t.contact_ahead_deg)
    ahead = [s for s in surfaces if abs(s.normal_rad) < ahead_rad]
    if ahead:
        short = max((max(0.0, sweep - s.dist_m) / math.cos(s.normal_rad) for s in ahead if s.dist_m is not None),
                    default=0.0)
        steps.append((max(t.contact_back_s, short / t.walk_speed_m_s), BACKWARD))
    beside = {side: max((max(0.0, sweep - s.dist_m) / abs(math.sin(s.normal_rad)) for s in surfaces
                         if s.dist_m is not None and abs(s.normal_rad) >= ahead_rad
                         and math.copysign(1.0, s.normal_rad) == side), default=0.0) for side in (1.0, -1.0)}
    if (beside[1.0] > 0.0) != (beside[-1.0] > 0.0):        # a surface alongside on one side only: step off it
        side = 1.0 if beside[1.0] > 0.0 else -1.0
        steps.append((beside[side] / t.side_speed_m_s, SIDE_RIGHT if side > 0 else SIDE_LEFT))
    turn = turn_clear_deg([math.degrees(s.normal_rad) for s in surfaces], t.contact_clear_deg, prefer)
    turn = math.copysign(max(t.contact_min_turn_deg, abs(turn)), turn if turn else prefer)
    steps.append((abs(turn) / t.turn_rate_deg_s, LEFT if turn > 0 else RIGHT))
    return steps


class WhiskerEvent(NamedTuple):
    """The whisker register: a TPSC contact (seed 3.2.12) as the node read it."""
    seq: int
    left: bool
    right: bool
    at: float                  # when it arrived
    alongside: bool = False    # one switch, IR clear, the sonar shows a wall at that outer wire (np3.NP3.wall_alongside)


def contact_plan(i: Mapping[str, Any], left: bool, right: bool, t: Tuning, alongside: bool = False) -> Steps:
    """The escape from what touches the body now: the IR beams' surfaces (or the whisker's guess) and the
    remembered echoes beside the body, in the body frame of the pose now. A wall alongside that touched one
    outer wire (IR clear): a sidestep away from it, no turn (D18, CHOICE: in a corridor 4 cm wider than the
    feet's reach a turn away from one wall faced the body at the other; corridor_narrow)."""
    ir = _seen(i.get("ir"))
    pose = i.get("pose")
    beside = body_frame(i.get("echoes"), pose) if pose is not None else []
    if alongside and left != right and not any(d is not None for d in ir):
        side = 1.0 if left else -1.0
        steps: Steps = [(t.contact_alongside_s, SIDE_RIGHT if left else SIDE_LEFT)]
        closing = wall_closing_deg(beside, side, t)
        if closing is not None and closing >= t.contact_alongside_min_deg:     # then parallel to it again
            steps.append((min(closing, t.contact_min_turn_deg) / t.turn_rate_deg_s, RIGHT if left else LEFT))
        return steps
    if left != right:
        obj_left = left                        # seed 3.2.12: OBJ_LEFT -> turn right
    else:                                      # the nearer side beam says where the object is
        obj_left = (ir[0] or math.inf) < (ir[-1] or math.inf)
    surfaces = sensed_surfaces(ir, 0.0 if left == right else (1.0 if left else -1.0), beside, t)
    return contact_steps(surfaces, -1.0 if obj_left else 1.0, t)    # square on: away from the touched side


def wall_closing_deg(points: list[Point], side: float, t: Tuning) -> float | None:
    """How far (deg) the wall alongside on `side` (+1 left) closes in on the heading ahead: the line fitted
    through the remembered echoes beside the body there (within contact_wall_reach_m of the axis, from the rear
    to avoid_echo_m ahead); None while fewer than 3 or spanning less than the body's half length."""
    pts = [(bx, by * side) for bx, by, _s, _a in points
           if t.body_half_width_m < by * side < t.contact_wall_reach_m and -t.body_half_length_m <= bx <= t.avoid_echo_m]
    if len(pts) < 3 or max(b for b, _ in pts) - min(b for b, _ in pts) < t.body_half_length_m:
        return None
    n = len(pts)
    mb, md = sum(b for b, _ in pts) / n, sum(d for _, d in pts) / n
    slope = sum((b - mb) * (d - md) for b, d in pts) / sum((b - mb) ** 2 for b, _ in pts)
    return -math.degrees(math.atan(slope))         # > 0: nearer ahead than behind


def contact_trigger(t: Tuning) -> Trigger:
    """seed 3.2.12, 3.2.13, 5.2: a whisker touches or an IR echo is almost at the body -> back off, turn away
    from the surface the IR beams (or the whisker) sense until it is behind the robot's side."""
    edge = _Edge()

    def trigger(i: Mapping[str, Any], now: float) -> Steps | None:
        raw = i.get("whisker")
        w = WhiskerEvent(*raw) if raw is not None else None     # a touch older than one hold is history
        touched = w is not None and edge.new(raw) and now - w.at <= t.reflex_hold_s
        left, right = (w.left, w.right) if touched and w is not None else (False, False)
        close = [d is not None and d < t.ir_contact_m for d in _seen(i.get("ir"))]
        if not (touched or any(close)):
            return None
        return contact_plan(i, left, right, t, alongside=touched and w is not None and w.alongside)
    return trigger


class Touch(NamedTuple):
    """A whisker touch the contact reflex planned on a guess (the IR beams saw nothing yet)."""
    at: float
    left: bool
    right: bool


class ContactModule(ReflexModule):
    """seed 3.2.12, 3.2.13, 5.2: the contact reflex. The TPSC reports a touch at once, the IRRC only when polled,
    so a touch often reaches the NP3 before the beams see what was touched: that escape is planned on a guess
    (the surface contact_whisker_normal_deg aside: no back-off, a short turn). When the beams see something
    within reflex_hold_s of the touch, the escape is planned again, once, from what they see in the body frame
    now. Kept on the guess, a block met square on (clutter seed 3: right whisker, then the IR 9 cm ahead) was
    turned from by 53 deg without backing off; the body stayed beside its face and the task turned back into
    its unseen corner, twice."""

    def __init__(self, t: Tuning) -> None:
        super().__init__("contact", REFLEXES, ("whisker", "ir", "pose", "echoes"), contact_trigger(t))
        self.t = t
        self.guess: Touch | None = None

    def step(self, inputs: Mapping[str, Any], now: float) -> Outputs:
        before = self.plan
        out = super().step(inputs, now)
        seen = any(d is not None for d in _seen(inputs.get("ir")))
        if self.plan is not None and self.plan is not before:          # a new escape
            raw = inputs.get("whisker")
            w = WhiskerEvent(*raw) if raw else None
            self.guess = Touch(now, bool(w.left), bool(w.right)) if w is not None and not seen else None
        elif self.plan is not None and self.guess is not None and seen:
            if now - self.guess.at <= self.t.reflex_hold_s:
                self.plan = Plan(contact_plan(inputs, self.guess.left, self.guess.right, self.t), now)
                out = {self.outputs[0]: self.plan.value(now)}
            self.guess = None
        return out


def pit_trigger(t: Tuning) -> Trigger:
    """seed 1.2.2 (sole switch), MMC NO_GROUND: a foot found no ground -> step away from that foot (back off
    from a front foot, walk on from a rear one, sidestep from a middle one), then turn away from its side.
    The register is (seq, foot x, foot y) in the body frame, or a bare count (a foot not known: back off)."""
    edge = _Edge()

    def trigger(i: Mapping[str, Any], now: float) -> Steps | None:
        pit = i.get("pit")
        if not edge.new(pit):
            return None
        fx, fy = (pit[1], pit[2]) if isinstance(pit, tuple) else (1.0, 0.0)
        turn = RIGHT if fy > 0 else LEFT
        if abs(fx) < 0.05:                      # a middle foot: the pit is beside the body
            return [(t.pit_back_s, SIDE_RIGHT if fy > 0 else SIDE_LEFT), (t.pit_turn_s, turn)]
        return [(t.pit_back_s, BACKWARD if fx > 0 else FORWARD), (t.pit_turn_s, turn)]
    return trigger


def uphill(tilt: Any) -> tuple[float, float]:
    """The ground's rise per metre in the body frame (forward, left) from the ISC's two axes (seed 3.2.14:
    0 longitudinal, nose up positive; 1 transverse, left side up positive)."""
    lon, tr = tilt or (0.0, 0.0)
    return math.tan(math.radians(lon)), math.tan(math.radians(tr))


def steepness_deg(tilt: Any) -> float:
    """The slope's own inclination, whatever the heading: a slope met diagonally splits it between the axes."""
    return math.degrees(math.atan(math.hypot(*uphill(tilt))))


def tilt_trigger(t: Tuning) -> Trigger:
    """seed 3.2.14, docs/decisions.md D8: dangerous inclination -> step straight downhill (back, forward or sideways,
    whichever is closest to the fall line), then turn until the slope is behind."""
    def trigger(i: Mapping[str, Any], now: float) -> Steps | None:
        if steepness_deg(i.get("tilt")) <= t.tilt_limit_deg:
            return None
        ux, uy = uphill(i.get("tilt"))
        if abs(ux) >= abs(uy):
            away = BACKWARD if ux > 0 else FORWARD
        else:
            away = SIDE_RIGHT if uy > 0 else SIDE_LEFT
        down = math.degrees(math.atan2(-uy, -ux))          # the fall line, body frame (ccw positive)
        turn = [(abs(down) / t.turn_rate_deg_s, LEFT if down > 0 else RIGHT)] if abs(down) > 20 else []
        return [(t.tilt_back_s, away), *turn]
    return trigger


def leg_blocked_trigger(t: Tuning) -> Trigger:
    """seed 6.1: a blocked leg -> hold still while its LCP retracts it and re-plans the swing, then step
    sideways away from the obstacle on that leg's side (walking on would press the legs against it)."""
    edge = _Edge()

    def trigger(i: Mapping[str, Any], now: float) -> Steps | None:
        b = i.get("leg_blocked")
        if not edge.new(b):
            return None
        away = SIDE_RIGHT if b[1] > 0 else SIDE_LEFT
        return [(t.leg_blocked_hold_s, STOP), (t.leg_blocked_side_s, away)]
    return trigger


def stop_while(register: str) -> Trigger:
    """Stop for as long as `register` is true (battery: 3.2.17; unreliable / failed IR: 6.2)."""
    return lambda i, now: [(T.NP3_PERIOD_S, STOP)] if i.get(register) else None


class EventModule:
    """A module that answers each new event on its one input with a timed plan, replacing a running one
    (a newer event knows better); it emits only while the plan runs."""

    outputs = ("move",)

    def __init__(self, name: str, layer: str, port: str, t: Tuning) -> None:
        self.name, self.layer, self.t, self.inputs = name, layer, t, (port,)
        self.edge = _Edge()
        self.plan: Plan | None = None

    def answer(self, event: Any) -> Steps | None:
        raise NotImplementedError

    def step(self, inputs: Mapping[str, Any], now: float) -> Outputs:
        event = inputs.get(self.inputs[0])
        if event is not None and self.edge.new(event[0]):
            steps = self.answer(event)
            if steps:
                self.plan = Plan(steps, now)
        if self.plan is not None and self.plan.value(now) is None:
            self.plan = None
        return {"move": self.plan.value(now) if self.plan else None}


class GuardModule(EventModule):
    """seed 5.1.2: the node's motion check refused the command the network chose (it would bring the body
    into something the sensors saw): do the safe alternative it found for guard_hold_s. Unlike the other
    reflexes a new refusal replaces a running plan at once (the alternative itself was refused)."""

    def __init__(self, t: Tuning) -> None:
        super().__init__("guard", REFLEXES, "veto", t)

    def answer(self, event: Any) -> Steps | None:
        return [(self.t.guard_hold_s, event[1])]


# --------------------------------------------------------------------------- the motion check (seed 5.1.2)
def velocity(cmd: Any, t: Tuning) -> tuple[float, float, float]:
    """Body-frame velocity (forward m/s, left m/s, counter-clockwise rad/s) a direction command gives."""
    v, u, w = t.walk_speed_m_s, t.side_speed_m_s, math.radians(t.turn_rate_deg_s)
    return {FORWARD: (v, 0.0, 0.0), BACKWARD: (-v, 0.0, 0.0), SIDE_LEFT: (0.0, u, 0.0), SIDE_RIGHT: (0.0, -u, 0.0),
            LEFT: (0.0, 0.0, w), RIGHT: (0.0, 0.0, -w)}.get(cmd, (0.0, 0.0, 0.0))


def body_gap(px: float, py: float, t: Tuning) -> float:
    """Distance from a body-frame point to the body's outline (0 on or inside it)."""
    dx, dy = abs(px) - t.body_half_length_m, abs(py) - t.body_half_width_m
    return math.hypot(max(dx, 0.0), max(dy, 0.0))


def closing_in(points: list[Point], cmd: Any, t: Tuning) -> float:
    """How far (m) the body's outline comes into the guard margin of a point it moves towards, following
    `cmd` for the guard horizon (0: the move is safe). Only points the motion brings closer count: a body
    already near a wall may still move away from it. A sonar echo comes as points across its beam, those a
    later ping showed free already gone (behaviours.np3, issue 17), so each point counts as it lies."""
    vx, vy, w = velocity(cmd, t)
    if vx == vy == w == 0.0:
        return 0.0
    reach = math.hypot(t.body_half_length_m, t.body_half_width_m) + t.guard_margin_m \
        + t.guard_horizon_s * max(abs(vx), abs(vy), abs(w) * t.body_half_length_m)
    near = [(bx, by) for bx, by, _seen, _arc in points if math.hypot(bx, by) <= reach]
    worst = 0.0
    steps = 10
    for px, py in near:
        d0 = body_gap(px, py, t)
        for k in range(1, steps + 1):
            s = t.guard_horizon_s * k / steps
            a = -w * s                              # the point as the moved body sees it
            qx, qy = px - vx * s, py - vy * s
            rx, ry = qx * math.cos(a) - qy * math.sin(a), qx * math.sin(a) + qy * math.cos(a)
            d = body_gap(rx, ry, t)
            if d < t.guard_margin_m and d < d0 - 1e-3:
                worst = max(worst, t.guard_margin_m - d)
    return worst


def safe_instead(points: list[Point], cmd: Any, t: Tuning, touched: float = 0.0) -> Any:
    """The command to give instead of an unsafe `cmd`: the closest safe alternative (turn the other way,
    turn towards the freer side, back off), STOP when nothing is safe. A turn refused whose other way turns
    towards the crowded side (a wall along one flank that also closes in ahead: the end swings into it one
    way, the nose the other) sidesteps away from that side first: turning back towards it undid the
    avoidance that had turned away, and the two took turns in front of the wall (scenarios/sonar_first.yaml).
    A walk refused turns first away from the side of the echoes it would close in on, whatever else lies round
    the body: choosing by the crowd turned the robot towards the very wall ahead of it (corridor_narrow seed 3:
    the right-hand wall 0.27 m ahead-right, the left-hand wall's echoes more numerous, the guard turned right);
    when that turn would swing the rear into what lies alongside, it sidesteps away from them instead of
    backing off (a corridor walked a few degrees off its axis: backing off and walking on met the same wall
    again and again, corridor_narrow seeds 18 and 19).
    `touched` (+1 left, -1 right, 0 none): a feeler on that side touched just now (NP3_TOUCH_FRESH_S); no
    alternative sidesteps or turns towards it. The touch is where a surface is now, the remembered echoes are
    where the drifting reckoning put them: a sidestep away from a wall touched, refused for an echo on the other
    side, became a sidestep into the wall (corridor_narrow seed 20, fourteenth session)."""
    crowd = sum(1 if by > 0 else -1 for bx, by, _s, _a in points if abs(bx) < 0.4 and abs(by) < 0.4)
    if cmd in (FORWARD, BACKWARD):
        crowd = sum(1 if p[1] > 0 else -1 for p in points if closing_in([p], cmd, t) > 0) or crowd
    freer = (RIGHT, LEFT) if crowd > 0 else (LEFT, RIGHT)
    away = SIDE_RIGHT if crowd > 0 else SIDE_LEFT
    options = {FORWARD: (freer[0], away, freer[1], BACKWARD) if crowd else (*freer, BACKWARD), BACKWARD: freer,
               LEFT: (RIGHT, BACKWARD, FORWARD),
               RIGHT: (LEFT, BACKWARD, FORWARD), SIDE_LEFT: (SIDE_RIGHT, *freer), SIDE_RIGHT: (SIDE_LEFT, *freer)}
    if crowd and cmd == freer[0]:                     # the other way is towards the crowded side
        options[cmd] = (away, *options[cmd])
    towards = {1.0: (SIDE_LEFT, LEFT), -1.0: (SIDE_RIGHT, RIGHT)}.get(touched, ())
    for alt in options.get(cmd, ()):
        if alt not in towards and closing_in(points, alt, t) == 0.0:
            return alt
    return STOP


class SonarFix(NamedTuple):
    """One sonar range at one scan angle, with where the dead reckoning had the body when it was pinged."""

    t: float
    metres: float
    x: float
    y: float


class PinnedCheck:
    """seed 5.1.2, issue 17: the body pressed against something no sensor sees. A post lower than the sonar
    head and thinner than the gap between the IR fan (+-15 deg from the nose: 2.6 cm either side of the axis at
    its 10 cm reach) and straight corner whiskers (8 cm out, angled outward; the feelers' lane wires close that
    gap now, docs/decisions.md D18) meets the body's front unseen; the legs then walk on the spot and the dead
    reckoning walks on (scenarios/posts_low.yaml with those whiskers and without this check: held for the
    whole run, 220 contacts). The sonar still hears the walls: walking forward, a range at a fixed scan
    angle changes with the body's progress unless the surface lies along the way. Pinned when, while FORWARD
    is walked (no step back or aside, no stop), pinned_angles angles on both sides of the axis each changed by
    less than pinned_change of the reckoned progress (at least pinned_progress_m) since a ping at that angle at most
    pinned_ref_s before, each comparison counting for pinned_window_s.
    Parallel walls leave the ranges unchanged too: remembered echoes beside the body say so (`alongside`),
    and then nothing is concluded."""

    def __init__(self, t: Tuning) -> None:
        self.t = t
        self.since: float | None = None                  # FORWARD walked without a break since
        self.fixes: dict[int, list[SonarFix]] = {}       # scan angle -> its pings since then
        self.still: dict[int, tuple[float, bool]] = {}   # scan angle -> (when, range unchanged) of its last comparison

    def command(self, now: float, cmd: Any) -> None:
        """The command the legs walk from now on (sent, or a reflex's at the MCP). A turn on the spot, the task's
        steering between two steps, is no break (the body does not move; a range at a fixed scan angle then
        changes with the heading, which only ever says "moved"); nor is a gait change."""
        if cmd in (LEFT, RIGHT) or cmd >= MovCmd.TRIPOD:
            return
        if cmd != FORWARD:
            self.since = None
            self.fixes.clear()
            self.still.clear()
        elif self.since is None:
            self.since = now

    def alongside(self, points: list[Point]) -> bool:
        """A remembered echo (body frame) beside the body: a wall along the way keeps the ranges as they were."""
        return any(abs(bx) <= self.t.body_half_length_m + self.t.pinned_beside_m and abs(by) <= self.t.pinned_beside_m
                   and abs(by) > self.t.body_half_width_m for bx, by, _s, _a in points)

    def heard(self, rel_deg: int, metres: float | None, fix_at: float, xy: tuple[float, float],
              alongside: bool) -> bool:
        """A sonar range at body angle rel_deg pinged at fix_at, the body reckoned at xy then: pinned now?
        `alongside`: what alongside() says of the remembered echoes now."""
        lo, hi = self.t.pinned_range_m
        if self.since is None or fix_at < self.since or metres is None or not lo <= metres <= hi:
            return False
        fix = SonarFix(fix_at, metres, *xy)
        past = [f for f in self.fixes.get(rel_deg, []) if fix_at - f.t <= self.t.pinned_ref_s]
        self.fixes[rel_deg] = past
        far = [f for f in past if math.hypot(fix.x - f.x, fix.y - f.y) >= self.t.pinned_progress_m]
        if far:
            ref = far[-1]
            progress = math.hypot(fix.x - ref.x, fix.y - ref.y)
            self.still[rel_deg] = (fix_at, abs(fix.metres - ref.metres) < self.t.pinned_change * progress)
            past[:] = past[past.index(ref):]          # older ones are further back still
        past.append(fix)
        recent = {a: s for a, (when, s) in self.still.items() if fix_at - when <= self.t.pinned_window_s}
        pinned = (len(recent) >= self.t.pinned_angles and all(recent.values()) and not alongside
                  and any(a > 0 for a in recent) and any(a < 0 for a in recent))
        if pinned:
            self.since = fix_at
            self.fixes.clear()
            self.still.clear()
        return pinned


def pinned_trigger(t: Tuning) -> Trigger:
    """Issue 17, seed 5.1.2: the body is pinned against something ahead no sensor sees (PinnedCheck) -> as for a
    touch ahead whose side is not known: back off, then turn until the front is behind the side, to the side
    the remembered echoes show clearer."""
    edge = _Edge()

    def trigger(i: Mapping[str, Any], now: float) -> Steps | None:
        if not edge.new(i.get("pinned")):
            return None
        pose = i.get("pose")
        pts = body_frame(i.get("echoes"), pose) if pose is not None else []
        prefer = 1.0 if freer_turn(pts, t) == LEFT else -1.0
        return contact_steps([Surface(0.0, t.body_half_length_m)], prefer, t)
    return trigger


# --------------------------------------------------------------------------- level 1: avoidance
def blocking_surface(points: list[Point], t: Tuning) -> Surface | None:
    """The surface the remembered echoes in the legs' way (clear_ahead's corridor, up to avoid_echo_m from the
    body centre) lie on: the line fitted through them (points all within a centimetre, e.g. one IR beam's
    repeated reading: a surface facing the body at them); its normal says from which side it faces the body.
    None when no echo is in the way."""
    way = [(bx, by) for bx, by, _seen, arc in points
           if t.body_half_length_m < bx < t.avoid_echo_m and abs(by) + arc < t.avoid_half_width_m]
    if not way:
        return None
    mx, my = sum(p[0] for p in way) / len(way), sum(p[1] for p in way) / len(way)
    if all(math.hypot(px - mx, py - my) < 0.01 for px, py in way):
        return Surface(math.atan2(my, mx), math.hypot(mx, my))
    return _line(way)


def freer_turn(pts: list[Point], t: Tuning) -> Any:
    """The turn (LEFT or RIGHT) after which the remembered echoes leave the legs' way clearer (one avoidance
    turn's worth); on a tie, the side with less in front of it."""
    turn_rad = math.radians(t.turn_rate_deg_s * t.avoid_turn_s)
    ahead = {c: clear_ahead(rotated(pts, sign * turn_rad), t.avoid_half_width_m, t.body_half_length_m)
             for c, sign in ((LEFT, 1.0), (RIGHT, -1.0))}
    if ahead[LEFT] != ahead[RIGHT]:
        return LEFT if ahead[LEFT] > ahead[RIGHT] else RIGHT
    crowd = [by for bx, by, _s, _a in pts if 0 < bx < 2 * t.avoid_echo_m and abs(by) < 3 * t.avoid_half_width_m]
    return RIGHT if sum(1 if by > 0 else -1 for by in crowd) > 0 else LEFT


def avoid_trigger(t: Tuning) -> Trigger:
    """seed 5.1.2: an obstacle ahead (IR centre or side beam, or the sonar looking ahead) -> turn away from it.
    Without an IR beam to say which side is nearer, the remembered echoes in the legs' way say it: turn away
    from the side the surface they lie on faces the body from (blocking_surface). Only a surface met square on
    leaves the side open; then it is chosen on the echo memory and kept while avoidance goes on (the next turn
    within avoid_keep_side_s): the sonar scans only ahead of the heading, so after a turn the memory shows the
    side turned to as seen and the other as unknown, and choosing again turned the robot back and forth in
    front of a wall (issue 17, scenarios/sonar_first.yaml). Keeping the side whatever the surface turned the
    robot into a corridor's wall it had come to face (corridor_narrow seed 2: three turns on to the right
    towards the right-hand wall, the body across the corridor, its rear swung into the other wall)."""
    last: list[tuple[float, Any]] = []          # (when, turn) of the last avoidance turn

    def trigger(i: Mapping[str, Any], now: float) -> Steps | None:
        left, centre, right = _seen(i.get("ir"))
        sonar = i.get("sonar_ahead_m")
        pose = i.get("pose")
        pts = body_frame(i.get("echoes"), pose) if pose is not None else []
        near = ((centre is not None and centre < t.avoid_centre_m)
                or any(d is not None and d < t.avoid_side_m for d in (left, right))
                or (sonar is not None and sonar < t.avoid_sonar_m)
                or clear_ahead(pts, t.avoid_half_width_m, t.body_half_length_m) < t.avoid_echo_m)   # legs' corridor
        if not near:
            return None
        surface = blocking_surface(pts, t)
        if left is not None or right is not None:
            turn = RIGHT if (left or math.inf) < (right or math.inf) else LEFT
        elif surface is not None and abs(surface.normal_rad) >= math.radians(t.avoid_square_deg):
            turn = RIGHT if surface.normal_rad > 0 else LEFT      # away from the side the surface faces it from
        elif last and now - last[0][0] <= t.avoid_turn_s + t.avoid_keep_side_s:
            turn = last[0][1]                  # still avoiding: on round the same way
        else:
            turn = freer_turn(pts, t)
        last[:] = [(now, turn)]
        return [(t.avoid_turn_s, turn)]
    return trigger


# --------------------------------------------------------------------------- level 2: the task
def heading_error(pose: tuple[float, float, float], bearing: float) -> float:
    """Signed angle (rad, counter-clockwise positive) from the robot's heading to `bearing`."""
    return (bearing - pose[2] + math.pi) % (2 * math.pi) - math.pi


Point = tuple[float, float, float, float]


def body_frame(echoes: Any, pose: tuple[float, float, float]) -> list[Point]:
    """Echo points (x, y, seen_deg, arc_m) in the robot's present body frame (x forward, y left)."""
    x, y, th = pose
    c, s = math.cos(th), math.sin(th)
    return [((ex - x) * c + (ey - y) * s, -(ex - x) * s + (ey - y) * c, seen, arc) for ex, ey, seen, arc in echoes or ()]


def rotated(points: list[Point], angle: float) -> list[Point]:
    """Body-frame points as the body sees them after turning on the spot by `angle` (rad, counter-clockwise)."""
    c, s = math.cos(angle), math.sin(angle)
    return [(bx * c + by * s, -bx * s + by * c, seen, arc) for bx, by, seen, arc in points]


def wall_beside(points: list[Point], reach_m: float = 0.8) -> tuple[float | None, float | None]:
    """(distance of the right-hand wall from the body centre, its angle to the heading in rad) from the echoes
    seen to the right (65..115 deg); the angle is a line fitted along the wall, None while too short."""
    side = [(bx, -by) for bx, by, seen, _arc in points if -115 <= seen <= -65 and 0 < -by < reach_m and -1.0 <= bx <= 0.6]
    near = [d for bx, d in side if abs(bx) <= 0.4]
    dist = min(near) if near else None
    if len(side) < 3 or max(b for b, _ in side) - min(b for b, _ in side) < 0.4:
        return dist, None
    n = len(side)
    mb, md = sum(b for b, _ in side) / n, sum(d for _, d in side) / n
    sbb = sum((b - mb) ** 2 for b, _ in side)
    slope = sum((b - mb) * (d - md) for b, d in side) / sbb
    return dist, math.atan(slope)       # > 0: the wall falls away to the right ahead


def clear_ahead(points: list[Point], half_width_m: float, beyond_m: float = 0.0) -> float:
    """Distance from the body centre to the nearest echo surely in the corridor the body (and legs) sweep
    walking on: a sonar echo whose cone also reaches outside it (a side wall seen at a slant) does not count,
    nor does one less than `beyond_m` ahead of the centre (beside the body: walking on cannot meet it)."""
    return min((bx for bx, by, _seen, arc in points if bx > beyond_m and abs(by) + arc < half_width_m),
               default=math.inf)


def light_gradient(samples: list[tuple[float, float, float]], min_spread: float,
                   prior: tuple[float, float] | None = None) -> tuple[float, float] | None:
    """Least-squares plane L = a + gx x + gy y through (x, y, L) samples; None while they are too close together.

    The LSC sits on the body's centre and reads the same in every heading, so
    the direction to the light only shows in how the reading changes with the
    position (dead reckoning): the plane's slope points up the gradient. With a
    `prior` (the last fit) the slope is pulled towards it (ridge, weight of samples
    min_spread apart): samples along a line then still correct the slope along
    it and keep the prior across it.
    """
    n = len(samples)
    if n < 3:
        return None
    mx = sum(s[0] for s in samples) / n
    my = sum(s[1] for s in samples) / n
    ml = sum(s[2] for s in samples) / n
    sxx = sum((s[0] - mx) ** 2 for s in samples)
    syy = sum((s[1] - my) ** 2 for s in samples)
    sxy = sum((s[0] - mx) * (s[1] - my) for s in samples)
    sxl = sum((s[0] - mx) * (s[2] - ml) for s in samples)
    syl = sum((s[1] - my) * (s[2] - ml) for s in samples)
    if prior is not None and n >= 2:
        lam = n * (min_spread / 2) ** 2
        sxx, syy, sxl, syl = sxx + lam, syy + lam, sxl + lam * prior[0], syl + lam * prior[1]
        det = sxx * syy - sxy * sxy
        return (syy * sxl - sxy * syl) / det, (sxx * syl - sxy * sxl) / det
    det = sxx * syy - sxy * sxy
    # the smaller spread (eigenvalue of the scatter matrix) must reach min_spread^2 per sample
    tr = sxx + syy
    small = tr / 2 - math.sqrt(max(0.0, tr * tr / 4 - det))
    if small < n * (min_spread / 2) ** 2 or det <= 0:
        return None
    return (syy * sxl - sxy * syl) / det, (sxx * syl - sxy * sxl) / det


class TaskModule:
    """Level 2: the current task (docs/decisions.md D8: wall following, seeking / avoiding light, exploring)."""

    inputs = ("ir", "whisker", "light", "pose", "goal", "echoes", "mapped")
    outputs = ("move",)

    def __init__(self, task: str, t: Tuning) -> None:
        if task not in TASKS:
            raise ValueError(f"unknown task {task!r}; one of {TASKS}")
        self.name, self.layer, self.task, self.t = "task", TASK, task, t
        self.plan: Plan | None = None
        self.samples: list[tuple[float, float, float]] = []
        self.light_seq: Any = None
        self.gradient: tuple[float, float] | None = None
        self.wander_at: float | None = None
        self.wanders = 0
        self.reached: Any = None
        self.obstacle_until = -math.inf
        self.wall_at: float | None = None
        self.detour_side = 0.0
        self.detour_until = -math.inf
        self.weave = 0.0
        self.weave_at: float | None = None
        self.dark_level: float | None = None     # log lux of the flat samples while no light shows (dark())
        self.dimmest = math.inf                  # the lowest log lux sampled (the room's ambient light)

    def step(self, inputs: Mapping[str, Any], now: float) -> Outputs:
        if self.task in ("seek_light", "avoid_light"):
            self._sample(inputs.get("light"), now)    # every sample, also while a manoeuvre runs
        if self.plan is not None:
            v = self.plan.value(now)
            if v is not None:
                return {"move": v}
            self.plan = None
        return {"move": getattr(self, f"_{self.task}")(inputs, now)}

    def _run(self, steps: Steps, now: float) -> Any:
        self.plan = Plan(steps, now)
        return self.plan.value(now)

    def _steer(self, pose: tuple[float, float, float], bearing: float) -> MovCmd:
        err = heading_error(pose, bearing)
        if abs(err) <= math.radians(self.t.heading_tol_deg):
            return FORWARD
        return LEFT if err > 0 else RIGHT

    def _idle(self, i: Mapping[str, Any], now: float) -> MovCmd:
        return STOP

    def _forward(self, i: Mapping[str, Any], now: float) -> MovCmd:
        return FORWARD

    def _wander(self, now: float) -> MovCmd:
        """No goal: walk straight, every so often turn to a new heading (alternately left and right, growing)."""
        if self.wander_at is None:
            self.wander_at = now + self.t.wander_s
        if now < self.wander_at:
            return FORWARD
        self.wander_at = now + self.t.wander_s
        self.wanders += 1
        turn = LEFT if self.wanders % 2 else RIGHT
        return self._run([(self.t.wander_turn_s * (1 + self.wanders % 3), turn)], now)

    def _explore(self, i: Mapping[str, Any], now: float) -> MovCmd:
        """seed 3.3.2: head for the frontier of the topological map the node builds; wander while there is none."""
        goal, pose = i.get("goal"), i.get("pose")
        if goal is not None and pose is not None and goal != self.reached:
            if math.hypot(goal[0] - pose[0], goal[1] - pose[1]) < self.t.goal_reached_m:
                self.reached = goal
            else:   # round what the echo memory shows across the way (seed 5.1.2), not into avoidance again
                return self._steer(pose, self._detour(i, pose, math.atan2(goal[1] - pose[1], goal[0] - pose[0]), now))
        return self._wander(now)

    def _wall_follow(self, i: Mapping[str, Any], now: float) -> MovCmd:
        """Right-hand wall at a band the sonar can hold (docs/decisions.md D8): sidesteps keep the distance, turns the angle.

        The wall's distance and direction come from the sonar echoes seen to the
        right over the last seconds (sector minima arrive ~8 s apart per angle),
        carried along by dead reckoning; the target keeps the feet (0.2 m out)
        off the wall. Sidesteps change the distance without swinging the body's
        ends round; a wall ahead is a corner: turn left once the side is clear.
        """
        t, pose = self.t, i.get("pose")
        if pose is None:
            return FORWARD
        pts = body_frame(i.get("echoes"), pose)
        dist, angle = wall_beside(pts)
        ir = _seen(i.get("ir"))
        front = clear_ahead(pts, t.wall_target_m - t.wall_deadband_m)
        side_s = lambda d: min(1.6, max(0.4, abs(d) / t.side_speed_m_s))     # noqa: E731
        if front < t.wall_corner_m or ir[1] is not None:
            if dist is not None and dist < t.wall_target_m - t.wall_deadband_m:
                return self._run([(side_s(t.wall_target_m - dist), SIDE_LEFT)], now)
            return self._run([(45.0 / t.turn_rate_deg_s, LEFT)], now)        # an inside corner: turn with it
        if dist is None:
            if self.wall_at is not None and now - self.wall_at > t.wall_lost_s:
                self.wall_at = now                   # lost it (an outside corner): turn right, walk on to find it
                return self._run([(45.0 / t.turn_rate_deg_s, RIGHT), (2.0, FORWARD)], now)
            return FORWARD
        self.wall_at = now
        err = dist - t.wall_target_m
        if abs(err) > t.wall_deadband_m:
            return self._run([(side_s(err), SIDE_RIGHT if err > 0 else SIDE_LEFT)], now)
        if angle is not None and abs(math.degrees(angle)) > t.wall_align_deg:
            turn = RIGHT if angle > 0 else LEFT
            return self._run([(abs(math.degrees(angle)) / t.turn_rate_deg_s, turn), (1.0, FORWARD)], now)
        return FORWARD

    def _sample(self, light: Any, now: float) -> None:
        """seed 3.2.16: a new LSC sample (log lux at the dead-reckoned pose) refits the gradient; a fit that
        fails (samples too close or in a line) keeps the last direction."""
        if light is None or light[0] == self.light_seq:
            return
        self.light_seq = light[0]
        self.samples = (self.samples + [light[1:]])[-self.t.light_samples:]
        if self.task == "seek_light":                 # avoiding light, a flat reading is where it wants to be
            self._darkness()
        if self.dark_level is not None:
            return
        fit = light_gradient(self.samples, self.t.light_min_spread_m, self.gradient)
        if fit is not None and self.gradient is None:
            self.plan = None                          # the probe has done its job: head for the light now
        self.gradient = fit or self.gradient

    def _darkness(self) -> None:
        """Enter or leave the dark state (dark()) with the newest sample."""
        logs = [s[2] for s in self.samples]
        self.dimmest = min(self.dimmest, logs[-1])
        flat = self.t.light_flat_log
        if self.dark_level is None and len(logs) >= self.t.light_samples \
                and max(logs) < min(logs) + flat and max(logs) < self.dimmest + flat:
            self.dark_level = max(logs)               # no light to climb: the gradient so far was noise
            self.gradient = None
        elif self.dark_level is not None and logs[-1] >= self.dark_level + flat:
            self.dark_level = None                    # a light shows: fit afresh, with no prior from the noise

    def dark(self) -> bool:
        """No light to follow: a full set of samples spanned less than light_flat_log (a few LSC steps of
        noise) at the dimmest level seen (flat and bright is at the lamp, or the LSC saturated there: stay),
        and no sample since has read that much brighter than they did. The hysteresis matters: a flat
        reading's noise spans 1-3 steps, and a state that flipped with it sent the robot after a gradient of
        noise (light_behind_wall seed 2, issue 17)."""
        return self.dark_level is not None

    def _seek_light(self, i: Mapping[str, Any], now: float) -> MovCmd:
        return self._light(i, now, sign=1.0)

    def _avoid_light(self, i: Mapping[str, Any], now: float) -> MovCmd:
        return self._light(i, now, sign=-1.0)

    def _light(self, i: Mapping[str, Any], now: float, sign: float) -> MovCmd:
        """Up (or down) the light gradient fitted over the last samples; probe in an L while it is unknown.

        The LSC reads log lux in 3.6 % steps every ~2.5 s, so the fit needs samples
        spread across the way as well as along it: the robot weaves, alternately
        light_weave_deg either side of the gradient every light_weave_s, and the
        fit over the latest samples never degenerates into a line (a failed fit
        keeps the last direction). Each leg's heading is the one nearest the
        target whose corridor the echo memory shows clear: an obstacle across
        the way is walked round along its edge (bug-style, seed 5.1.2). Seeking
        a light none of the samples shows (all within light_flat_log: a lamp
        behind a wall), the robot explores its map (planned routes, seed 3.3.2)
        until it does.
        """
        t = self.t
        pose = i.get("pose")
        if sign > 0 and self.dark():
            return self._explore(i, now)
        ir = _seen(i.get("ir"))
        if self.gradient is None or pose is None:
            if any(d is not None for d in ir):
                self.obstacle_until = now + t.light_probe_s / 2    # after an obstacle, walk on past it first
            if now < self.obstacle_until:
                return FORWARD
            return self._run([(t.light_probe_s, FORWARD), (90.0 / t.turn_rate_deg_s, LEFT)], now)
        gx, gy = self.gradient
        bearing = math.atan2(sign * gy, sign * gx)
        flip = self.weave_at is None or now >= self.weave_at
        if flip:
            self.weave_at = now + t.light_weave_s
            self.weave = -self.weave or 1.0
        target = self._detour(i, pose, bearing + self.weave * math.radians(t.light_weave_deg), now)
        err = heading_error(pose, target)
        if flip and abs(err) > math.radians(t.heading_tol_deg) / 4:     # each leg starts on its heading
            return self._run([(abs(math.degrees(err)) / t.turn_rate_deg_s, LEFT if err > 0 else RIGHT)], now)
        return self._steer(pose, target)

    def _detour(self, i: Mapping[str, Any], pose: tuple[float, float, float], bearing: float, now: float) -> float:
        """seed 5.1.2: the heading closest to `bearing` whose corridor (body and legs) the echoes of the last
        seconds and the obstacles on the map (3.3.2) leave clear for t.light_clear_m; the side a detour took is
        kept for t.light_detour_hold_s after the last blocked heading (round an obstacle on one side, no
        dithering at its corner). The map matters at a long obstacle: the echo memory keeps its face only
        for seconds, a heading it no longer shows blocked turned the robot back into the face and avoidance
        turned it away again, for 50-100 s at seek_light's block (seeds 14, 16, issue 17)."""
        t = self.t
        echoes = tuple(i.get("echoes") or ()) + tuple(i.get("mapped") or ())
        if now > self.detour_until:
            self.detour_side = 0.0
        if not echoes:
            return bearing
        step = math.radians(t.light_detour_step_deg)
        sides = (self.detour_side,) if self.detour_side else (1.0, -1.0)
        if sides == (1.0, -1.0) and heading_error(pose, bearing) < 0:
            sides = (-1.0, 1.0)                            # look first on the side the robot already faces
        for k in range(int(round(math.pi / step)) + 1):
            for side in sides:
                h = bearing + side * k * step
                if clear_ahead(body_frame(echoes, (pose[0], pose[1], h)), t.avoid_half_width_m) >= t.light_clear_m:
                    if k:
                        self.detour_side, self.detour_until = side, now + t.light_detour_hold_s
                    return h
        return bearing


class OrientModule(EventModule):
    """Task level: turn towards a sound event (seed 3.2.7 APU/SDF direction, body frame, ccw from forward)."""

    def __init__(self, t: Tuning) -> None:
        super().__init__("orient", TASK, "sound", t)

    def answer(self, event: Any) -> Steps | None:
        err = (event[1] + 180) % 360 - 180          # -180..180, positive: to the left
        if abs(err) <= self.t.sound_min_deg:
            return None
        return [(abs(err) / self.t.turn_rate_deg_s, LEFT if err > 0 else RIGHT)]


# --------------------------------------------------------------------------- the network
def np3_network(clock: Clock, task: str = "forward", tuning: Tuning | None = None) -> Network:
    """The NP3's layered network; its actuator "move" is the Mov_Cmd for the MMC (3.2.3). Sensors: SENSORS."""
    t = tuning or Tuning()
    net = Network(clock)
    reflexes = [   # level 0; declared weakest first: a later suppressor sits closer to the MMC and wins
        ReflexModule("leg_blocked", REFLEXES, ("leg_blocked",), leg_blocked_trigger(t)),   # seed 6.1
        ContactModule(t),                                                                  # seed 3.2.12, 3.2.13, 5.2
        ReflexModule("pinned", REFLEXES, ("pinned", "pose", "echoes"), pinned_trigger(t)),  # seed 5.1.2, issue 17
        ReflexModule("pit", REFLEXES, ("pit",), pit_trigger(t)),                           # seed 1.2.2
        ReflexModule("tilt", REFLEXES, ("tilt",), tilt_trigger(t)),                        # seed 3.2.14
        ReflexModule("ir_fault", REFLEXES, ("ir_fault",), stop_while("ir_fault")),        # seed 6.2: IR -> stop
        ReflexModule("battery", REFLEXES, ("battery_low",), stop_while("battery_low")),   # seed 3.2.17: stop
    ]
    avoid = ReflexModule("avoid", AVOIDANCE, ("ir", "sonar_ahead_m", "pose", "echoes"), avoid_trigger(t))    # seed 5.1.2
    task_module = TaskModule(task, t)
    orient = OrientModule(t)
    reflexes.append(GuardModule(t))                                                        # seed 5.1.2: no collision
    for m in (task_module, orient, avoid, *reflexes):
        net.add(m)
    for m in net.modules.values():
        for p in m.inputs:
            net.wire(f"sensor.{p}", f"{m.name}.{p}")
    move = net.actuator("move")
    net.wire("task.move", move)
    net.suppress("orient.move", move, t.avoid_hold_s)         # a sound interrupts the task (seed 3.2.7)
    net.suppress("avoid.move", move, t.avoid_hold_s)          # seed 5.2: collision handling interrupts navigation
    for r in reflexes:
        net.suppress(f"{r.name}.move", move, t.reflex_hold_s)
    return net


__all__ = ["WhiskerEvent", "uphill", "steepness_deg", "Tuning", "TaskModule", "OrientModule", "np3_network", "light_gradient", "heading_error", "SENSORS",
           "closing_in", "safe_instead", "body_frame", "PinnedCheck",
           "REFLEXES", "AVOIDANCE", "TASK", "TASKS"]
