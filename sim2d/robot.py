"""The robot body, its six legs and their servos; the body moves with its stance feet.

Feet are kinematic points: a foot on the ground stays where it touched down
(its anchor), and each physics step the body pose is the least-squares rigid
transform that best keeps the stance feet on their anchors. The chassis is a
pymunk shape, used only to detect contact with walls and tall obstacles: a
move into one is refused (the feet slip). A foot in the air that runs into a
solid taller than itself slides along its face and down it; where the face
refuses more of the move than the foot makes, the servos draw stall current
(seed 6.1: the LCP sees the leg blocked).

Servos (seed 3.2.18): the JAC drives each one with a speed command
(`set_joint_drive`, rad/s, limited by the servo's top speed) and closes the
position loop itself; `set_joint_target` is a position servo for tests that
drive the legs without the network. Each servo's winding warms with the
square of its current and cools towards the air around the robot
(first-order thermal model, CHOICE constants in RobotParams).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import pymunk

from behaviours.kinematics import fk, ik
from sim2d.geometry import Pt, convex_hull, inside_convex, rigid_fit, to_body, to_world
from sim2d.robot_params import RobotParams
from sim2d.world import BODY, OBSTACLE, WALL, SolidHit, World

CONTACT_EPS = 0.002   # a foot within 2 mm of the ground touches it
DEPTH_EPS = 1e-6      # a swing foot moving this much further into a solid's footprint is blocked
LEG_REACH = 0.45      # body centre to the farthest foot, with margin
SLIDE_SPEED = 0.05    # m/s: a foot pushing into a face that moves slower than this (along it or down) stalls
FACE_FRICTION = 0.5   # CHOICE: a foot slides along a face only if its move along it exceeds this x its push into it
FACE_SKIN = 0.005     # CHOICE: a foot below a solid's top and within 5 mm inside its outline is at its face, not on top


@dataclass
class Joint:
    angle: float
    target: float
    current: float = 0.0
    speed: float = 0.0
    powered: bool = True
    rate: float = math.inf      # commanded speed (rad/s); the servo's own limit still applies
    drive: float | None = None  # speed command from the JAC (rad/s); None: position mode (target, rate)
    temperature: float = 20.0   # winding temperature, degrees C


@dataclass
class Leg:
    index: int
    joints: list[Joint]
    foot: tuple[float, float, float] = (0.0, 0.0, 0.0)   # body frame + height
    world: Pt = (0.0, 0.0)
    contact: bool = False
    anchor: Pt | None = None
    blocked: bool = False
    over_pit: bool = False

    @property
    def powered(self) -> bool:
        return all(j.powered for j in self.joints)


@dataclass
class Events:
    collisions: int = 0
    colliding: bool = False
    blocked_legs: int = 0
    pit_feet: int = 0
    unstable_steps: int = 0
    fell: bool = False
    contact_points: list[Pt] = field(default_factory=list)


@dataclass
class BatteryLog:
    """The battery's terminal voltage and current at every physics step, and the servos drawing stall current
    (issue 18: a load dip that the PSC could take for under-voltage, and what caused it, visible at a glance)."""
    v_min: float = math.inf
    v_sum: float = 0.0
    i_max: float = 0.0
    i_sum: float = 0.0
    steps: int = 0
    stall_steps: int = 0                  # servo-steps at stall current
    stall_run: dict[tuple[int, int], int] = field(default_factory=dict)   # (leg, joint) -> steps stalled in a row
    stall_run_max: int = 0

    def add(self, volts: float, amps: float, stalled: list[tuple[int, int]]) -> None:
        self.v_min = min(self.v_min, volts)
        self.v_sum += volts
        self.i_max = max(self.i_max, amps)
        self.i_sum += amps
        self.steps += 1
        self.stall_steps += len(stalled)
        self.stall_run = {k: self.stall_run.get(k, 0) + 1 for k in stalled}
        self.stall_run_max = max(self.stall_run_max, max(self.stall_run.values(), default=0))


def _top_reachable(solid: SolidHit, old_z: float) -> bool:
    """Whether a foot in the air inside a solid's outline may stand on its top.

    Only if it was above the top before this step (it came down onto it), or is deeper inside the outline than
    FACE_SKIN (the body carried it well in: it is not at a face). A foot below the top that entered a fraction
    of a mm sideways, the body carrying it, is at the face: it stalls there (seed 6.1) instead of counting as
    on top after one 10 ms step that no LCP poll sees (fault_battery_and_leg lost its blocked-leg event)."""
    return solid.depth <= 0.0 or old_z >= solid.height - CONTACT_EPS or solid.depth > FACE_SKIN


def _ccw(pts: list[Pt]) -> list[Pt]:
    (ax, ay), (bx, by), (cx, cy) = pts
    return pts if (bx - ax) * (cy - ay) - (by - ay) * (cx - ax) > 0 else [pts[0], pts[2], pts[1]]


class Robot:
    def __init__(self, p: RobotParams, world: World, pose: tuple[float, float, float]):
        self.p = p
        self.world = world
        self.pose = pose
        self.events = Events()
        self.legs: dict[int, Leg] = {}
        for i in p.legs:
            nx, ny = p.neutral_foot(i)
            q = ik(p, i, nx, ny, 0.0)
            self.legs[i] = Leg(i, [Joint(a, a) for a in q])
            self._update_foot(self.legs[i])
            self.legs[i].contact = True
            self.legs[i].anchor = self.legs[i].world
        self.ambient = world.temperature(pose[0], pose[1])
        for leg in self.legs.values():
            for j in leg.joints:
                j.temperature = self.ambient
        self.charge_used_ah = 0.0
        self.current = 0.0
        self.battery_log = BatteryLog()
        self.body = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
        half_l, half_w = p.body_length / 2, p.body_width / 2
        self.outline_body = [(half_l, half_w), (-half_l, half_w), (-half_l, -half_w), (half_l, -half_w)]
        self.shape = pymunk.Poly(self.body, self.outline_body)
        self.shape.filter = pymunk.ShapeFilter(categories=BODY, mask=WALL | OBSTACLE)
        world.space.add(self.body, self.shape)
        self._place(pose)

    # --- helpers -----------------------------------------------------------
    def outline(self) -> list[Pt]:
        return [to_world(self.pose, x, y) for x, y in self.outline_body]

    def _place(self, pose: tuple[float, float, float]) -> None:
        self.body.position = (pose[0], pose[1])
        self.body.angle = pose[2]
        self.world.space.reindex_shapes_for_body(self.body)

    def _update_foot(self, leg: Leg) -> None:
        q1, q2, q3 = (j.angle for j in leg.joints)
        leg.foot = fk(self.p, leg.index, q1, q2, q3)
        leg.world = to_world(self.pose, leg.foot[0], leg.foot[1])

    def _collides(self) -> bool:
        for hit in self.world.space.shape_query(self.shape):
            if self.world.heights.get(hit.shape, 0.0) > self.p.body_clearance:
                return True
        return False

    def set_joint_target(self, leg: int, joint: int, angle: float, rate: float = math.inf) -> None:
        """Position mode: the servo runs to `angle` at `rate` (tests driving the legs without JACs)."""
        j = self.legs[leg].joints[joint - 1]
        j.target, j.rate, j.drive = angle, rate, None

    def set_joint_drive(self, leg: int, joint: int, rate: float | None) -> None:
        """Speed mode (the JAC's output stage): turn at `rate` rad/s; None: no pulses, the servo goes limp."""
        j = self.legs[leg].joints[joint - 1]
        if rate is None:
            j.powered, j.drive = False, 0.0
        else:
            j.powered, j.drive = True, rate

    def warm_servos(self, dt: float) -> None:
        """CHOICE: first-order thermal model, dT/dt = (P * R_th - (T - T_air)) / tau with P = I^2 R."""
        p = self.p
        air = self.ambient = self.world.temperature(self.pose[0], self.pose[1])
        k = dt / p.servo_thermal_tau_s
        for leg in self.legs.values():
            for j in leg.joints:
                rise = j.current * j.current * p.servo_winding_ohm * p.servo_thermal_k_per_w
                j.temperature += (air + rise - j.temperature) * k

    # --- one physics step -----------------------------------------------------
    def step(self, dt: float) -> None:
        if self.events.fell:
            return
        p = self.p
        max_step = p.servo_speed * dt
        total_current = p.electronics_a
        near_solid, near_ground = self.world.near(self.pose[0], self.pose[1], LEG_REACH)
        near = near_solid or near_ground
        for leg in self.legs.values():
            if not leg.powered:
                leg.contact, leg.anchor = False, None      # an unpowered leg folds up (CHOICE)
                for j in leg.joints:
                    j.current = j.speed = 0.0
                continue
            old = [j.angle for j in leg.joints]
            moving = False
            for j in leg.joints:
                if j.drive is not None:
                    d = max(-max_step, min(max_step, j.drive * dt))
                else:
                    err = j.target - j.angle
                    lim = max_step if j.rate * dt > max_step else j.rate * dt
                    d = err if abs(err) <= lim else math.copysign(lim, err)
                j.angle += d
                j.speed = d / dt
                moving = moving or abs(d) > 1e-9
            if not moving and not leg.blocked:
                for j in leg.joints:
                    j.current = p.servo_idle_a
                total_current += 3 * p.servo_idle_a
                continue
            old_foot, old_world = leg.foot, leg.world
            self._update_foot(leg)
            fz = leg.foot[2]
            leg.blocked = False
            was = leg.contact
            if not near or (fz > self.world.max_ground + CONTACT_EPS and not near_solid):
                ground = 0.0                      # fast path: nothing around can touch this foot
                leg.over_pit = False
            else:
                under = math.inf
                if not was and moving and self.world.has_solids:
                    self._meet_solids(leg, old, old_foot, old_world, dt)
                    # a foot in the air that met an obstacle too tall to step onto is at its face, not on it
                    under = max(old_foot[2] + CONTACT_EPS, p.step_limit)
                    solid = self.world.solid_at(*leg.world, to_world(self.pose, *p.hip(leg.index)))
                    if not _top_reachable(solid, old_foot[2]):
                        under = min(under, solid.height - CONTACT_EPS)   # ... nor is one below a low bar's top
                ground = self.world.ground_height(*leg.world, under)
                leg.over_pit = ground is None
            leg.contact = ground is not None and leg.foot[2] <= ground + CONTACT_EPS
            if leg.contact and not was:
                leg.anchor = leg.world
            elif not leg.contact:
                leg.anchor = None
            if leg.over_pit and leg.foot[2] <= CONTACT_EPS:
                self.events.pit_feet += 1
            for j in leg.joints:
                pushing = abs(j.drive) > 1e-6 if j.drive is not None else abs(j.target - j.angle) > 1e-6
                if leg.blocked and pushing:
                    j.current = p.servo_stall_a
                elif abs(j.speed) > 1e-9:
                    j.current = p.servo_move_a
                else:
                    j.current = p.servo_idle_a
                total_current += j.current
        self._move_body()
        self.warm_servos(dt)
        self.current = total_current
        self.charge_used_ah += total_current * dt / 3600.0
        stalled = [(leg.index, k) for leg in self.legs.values() for k, j in enumerate(leg.joints, 1)
                   if j.current >= p.servo_stall_a]
        self.battery_log.add(self.battery_voltage(), total_current, stalled)

    def _meet_solids(self, leg: Leg, old: list[float], old_foot: tuple[float, float, float], old_world: Pt,
                     dt: float) -> None:
        """A foot in the air that moves into a wall or obstacle taller than itself.

        From the side (the foot was below the top before) it meets a face; from above it lands on top (contact,
        below). A foot the body carried into a footprint while it was in the air is not stuck there: only a move
        that takes it into the solid, or deeper, meets the face. There the foot slides along the face and down
        it: only the part of the move into the face is refused (issue 17/18: a foot hung on a wall's face found
        no ground and read as a pit; a foot set down beside a wall stalled on its face). A foot that barely moves
        (slower than SLIDE_SPEED) while it pushes stalls its servos (seed 6.1: the swing is blocked)."""
        fz = leg.foot[2]
        hip = to_world(self.pose, *self.p.hip(leg.index))
        solid = self.world.solid_at(*leg.world, hip)
        if not (solid.height > fz + CONTACT_EPS and old_foot[2] < solid.height - CONTACT_EPS):
            return
        before = self.world.solid_at(*old_world, hip).depth + DEPTH_EPS
        if solid.depth <= before:
            return
        (ox, oy), (wx, wy), (nx, ny) = old_world, leg.world, solid.normal
        dx, dy = wx - ox, wy - oy
        into = min(0.0, dx * nx + dy * ny)                      # the push into the face (normal: out of it)
        tx, ty = dx - into * nx, dy - into * ny                 # ... and the part along it
        made, refused = 0.0, math.dist(old_world, leg.world)
        # friction: a foot meeting the face more squarely than the friction cone allows does not slide along it
        slides = math.hypot(tx, ty) >= FACE_FRICTION * -into
        for cx, cy in ([(ox + tx, oy + ty)] if slides else []) + [old_world]:   # along the face; straight down
            if self.world.solid_at(cx, cy, hip).depth > before:
                continue
            q = ik(self.p, leg.index, *to_body(self.pose, cx, cy), fz)
            foot = fk(self.p, leg.index, *q)
            moved = to_world(self.pose, foot[0], foot[1])
            if self.world.solid_at(*moved, hip).depth > before:
                continue                                        # the leg's reach clamped it back into the face
            made = math.dist(moved, old_world) + abs(foot[2] - old_foot[2])
            refused = math.dist(moved, leg.world) + abs(foot[2] - fz)
            for j, a, b in zip(leg.joints, q, old):
                j.angle, j.speed = a, (a - b) / dt
            leg.foot, leg.world = foot, moved
            break
        else:
            for j, a in zip(leg.joints, old):
                j.angle, j.speed = a, 0.0
            leg.foot, leg.world = old_foot, old_world
        if refused > 0.0 and made < SLIDE_SPEED * dt:
            leg.blocked = True                                  # seed 6.1: the swing foot hits an obstacle
            self.events.blocked_legs += 1

    def _move_body(self) -> None:
        stance = [leg for leg in self.legs.values() if leg.contact and leg.anchor is not None]
        if len(stance) < 3:
            self.events.unstable_steps += 1
            self._check_fall()
            return
        anchors = [leg.anchor for leg in stance]
        hull = _ccw(anchors) if len(anchors) == 3 else convex_hull(anchors)
        new = rigid_fit([(leg.foot[0], leg.foot[1]) for leg in stance], [leg.anchor for leg in stance])
        if not inside_convex(new[0], new[1], hull):
            self.events.unstable_steps += 1
            self._check_fall()
            return
        old = self.pose
        self.pose = new
        self._place(new)
        if self._collides():
            self.pose = old
            self._place(old)
            if not self.events.colliding:
                self.events.collisions += 1
            self.events.colliding = True
            for leg in stance:            # the feet slip: re-anchor where they are now
                leg.world = to_world(old, leg.foot[0], leg.foot[1])
                leg.anchor = leg.world
        else:
            self.events.colliding = False
        for leg in self.legs.values():
            leg.world = to_world(self.pose, leg.foot[0], leg.foot[1])

    def _check_fall(self) -> None:
        """The body drops into a pit when it is over one without support."""
        if self.world.in_pit(self.pose[0], self.pose[1]):
            self.events.fell = True

    # --- proprioception ---------------------------------------------------------
    def battery_emf(self) -> float:
        """seed 3.2.17: open-circuit volts, linear in the state of charge over the 4.2 .. 5.0 V window."""
        p = self.p
        soc = max(0.0, 1.0 - self.charge_used_ah / p.battery_ah)
        return p.battery_empty_v + (p.battery_full_v - p.battery_empty_v) * soc

    def battery_voltage(self) -> float:
        """Terminal volts: the open-circuit voltage less the drop across the internal resistance under load."""
        return self.battery_emf() - self.p.battery_r_ohm * self.current
