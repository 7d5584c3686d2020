"""The simulation: world, robot, sensors, buses and the 39 node processes on one clock.

One discrete-event scheduler drives everything: the physics step is a
periodic event (fixed dt), bus frames are events at their start and end,
node timers are events. Nothing is stepped per bit or per byte.
"""
from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass, field
from typing import Any

from sim2d import encodings
from sim2d.behaviours import behaviour
from sim2d.behaviours.base import NodeProcess
from sim2d.bus import Bus, Fault as BusFault, TraceEntry
from sim2d.codec import Codec, Decoded
from sim2d.events import Scheduler
from sim2d.geometry import point_in_polygon
from sim2d.post import Verdict
from sim2d.rng import stream
from sim2d.robot import Robot
from sim2d.robot_params import DEFAULT, RobotParams
from sim2d.scenario import Scenario
from sim2d.sensors import Sensors
from sim2d.world import World

POSE_SAMPLE_S = 0.1       # pose log resolution (trace hash, plot)
CLEARANCE_SAMPLE_S = 0.05
TILT_LIMIT_DEG = 20.0     # CHOICE: a "dangerous inclination" event (seed 1.2.2) starts above this


FrameRecord = TraceEntry     # one frame on a wire: times, bus, sender, bytes sent and heard, flags


@dataclass
class Result:
    scenario: Scenario
    verdict: Verdict | None
    frames: list[FrameRecord]
    poses: list[tuple[float, float, float, float]]
    metrics: dict[str, Any]
    trace_hash: str
    sensors: Any
    world: World
    robot: Robot
    frames_png: list = field(default_factory=list)


class Context:
    """What a node process may reach: the clock, the codec, its buses and the physics."""

    def __init__(self, sim: "Simulation"):
        self.sim = sim
        self.sched = sim.sched
        self.spec = sim.spec
        self.codec = sim.codec
        self.buses = sim.buses
        self.params = sim.params
        self.robot = sim.robot
        self.sensors = sim.sensors
        self.scenario = sim.scenario
        self._cache: dict[bytes, Decoded | None] = {}

    def decode(self, data: bytes) -> Decoded | None:
        c = self._cache
        if data in c:
            return c[data]
        if len(c) > 20000:
            c.clear()
        d = c[data] = self.codec.decode(data)
        return d

    def _slot(self, bus: str) -> float:
        b = self.buses[bus]
        return b.frame_time(self.spec.frame.overhead) + b.turnaround

    def backoff(self, bus: str, address: int) -> float:
        """Spec arbitration address_backoff: (rank + 1) slots, rank by ascending address."""
        slaves = sorted(n.address for n in self.spec.slaves(bus))
        rank = slaves.index(address) if address in slaves else len(slaves)
        return (rank + 1) * self._slot(bus)

    def master_gap(self, bus: str) -> float:
        """A master starts a new transaction one request slot after the line went idle."""
        return self._slot(bus)

    def master_of(self, bus: str) -> str:
        return self.spec.buses[bus].master

    def record_post(self, short: str, missing: list[int]) -> None:
        self.sim.post_reports[short] = (self.sched.now, missing)

    def set_verdict(self, v: Verdict) -> None:
        self.sim.verdict = v
        self.sim.verdict_time = self.sched.now

    def move_received(self, t: float, mov_cmd: int) -> None:
        self.sim.moves.append((t, mov_cmd))

    def stimulus(self, t: float, kind: str = "") -> None:
        self.sim.stimuli.append((t, kind))

    def escaping(self, start: float, end: float) -> None:
        self.sim.escapes.append((start, end))

    def event(self, kind: str, t: float, leg: int) -> None:
        self.sim.events.append((t, kind, leg))


class Simulation:
    def __init__(self, scenario: Scenario, spec: Any, params: RobotParams = DEFAULT, keep_frames_every: float | None = None):
        self.scenario, self.spec, self.params = scenario, spec, params
        self.sched = Scheduler()
        encodings.use_spec(spec)
        self.codec = Codec(spec)
        self.world = World(scenario)
        self.robot = Robot(params, self.world, scenario.start)
        self.sensors = Sensors(self.world, self.robot, scenario.seed)
        self.frames: list[FrameRecord] = []
        self.buses: dict[str, Bus] = {}
        for name, b in spec.buses.items():
            self.buses[name] = Bus(name, self.sched, b.baud, b.bits_per_char, b.turnaround_us * 1e-6,
                                   stream(scenario.seed, f"bus:{name}"), self._trace)
        self.ctx = Context(self)
        self.nodes: dict[str, NodeProcess] = {}
        self.verdict: Verdict | None = None
        self.verdict_time: float | None = None
        self.post_reports: dict[str, tuple[float, list[int]]] = {}
        self.moves: list[tuple[float, int]] = []
        self.stimuli: list[tuple[float, str]] = []
        self.escapes: list[tuple[float, float]] = []
        self.events: list[tuple[float, str, int]] = []
        self.poses: list[tuple[float, float, float, float]] = []
        self.distance = 0.0
        self.min_clearance = math.inf
        self.tilt_events = 0
        self.max_tilt = 0.0
        self._tilted = False
        self.reach_time: float | None = None
        self.entered_time: float | None = None
        self.snapshots: list[tuple[float, tuple[float, float, float], list]] = []
        self.keep_frames_every = keep_frames_every
        absent = set(scenario.absent)
        for n in spec.nodes:
            if n.short in absent:
                continue
            proc = behaviour(n.role)(n, self.ctx)
            self.nodes[n.short] = proc
            for bus in (n.bus, n.masters):
                if bus is not None:
                    proc.attach(bus, self.buses[bus].attach(n.short, proc.on_bytes, proc.on_echo))
        # a JAC that is absent, or whose LCP is, never gets a set-point: its servo is limp (CHOICE)
        for n in spec.role_nodes("JAC"):
            lcp = next(m for m in spec.role_nodes("LCP") if m.leg == n.leg)
            if n.short in absent or lcp.short in absent:
                self.robot.legs[n.leg].joints[n.joint - 1].powered = False

    # --- trace ------------------------------------------------------------------
    def _trace(self, e: TraceEntry) -> None:
        self.frames.append(e)      # decoded only when written: the bytes determine the text

    # --- faults --------------------------------------------------------------------
    def _schedule_faults(self) -> None:
        for f in self.scenario.faults:
            if f.kind == "bus":
                self.sched.at(f.at, self._set_bus_fault, f.bus, BusFault(f.loss, f.corrupt, f.delay))
                if f.until is not None:
                    self.sched.at(f.until, self._set_bus_fault, f.bus, BusFault())
            elif f.node in self.nodes:
                if f.kind == "kill":
                    self.sched.at(f.at, self._kill, f.node)
                else:
                    self.sched.at(f.at, self._mute, f.node, True)
                    if f.until is not None:
                        self.sched.at(f.until, self._mute, f.node, False)

    def _set_bus_fault(self, bus: str, fault: BusFault) -> None:
        self.buses[bus].fault = fault

    def _kill(self, short: str) -> None:
        proc = self.nodes[short]
        proc.kill()
        for port in proc.ports.values():
            port.killed = True
            port.queue.clear()
        self.events.append((self.sched.now, "kill", 0))

    def _mute(self, short: str, on: bool) -> None:
        for port in self.nodes[short].ports.values():
            port.muted = on

    # --- clock ------------------------------------------------------------------------
    def _every(self, period: float, fn: Any) -> None:
        def run() -> None:
            fn(self.sched.now)
            self.sched.after(period, run)
        self.sched.at(self.sched.now, run)

    def _physics(self, t: float) -> None:
        r = self.robot
        x0, y0, _ = r.pose
        r.step(self.params.dt)
        x, y, th = r.pose
        self.distance += math.hypot(x - x0, y - y0)
        exp = self.scenario.expect.reach
        if exp is not None and self.reach_time is None and point_in_polygon(x, y, exp[0]):
            self.reach_time = t
        out = self.scenario.expect.stay_out
        if out is not None and self.entered_time is None and point_in_polygon(x, y, out):
            self.entered_time = t

    def _sample(self, t: float) -> None:
        x, y, th = self.robot.pose
        self.poses.append((round(t, 6), x, y, th))
        tilt = self.sensors.tilt_deg()
        self.max_tilt = max(self.max_tilt, tilt)
        if tilt > TILT_LIMIT_DEG and not self._tilted:
            self.tilt_events += 1
        self._tilted = tilt > TILT_LIMIT_DEG
        if self.keep_frames_every and (not self.snapshots or t - self.snapshots[-1][0] >= self.keep_frames_every - 1e-9):
            self.snapshots.append((t, self.robot.pose, [leg.world for leg in self.robot.legs.values()]))

    def _clearance(self, t: float) -> None:
        c = self.world.clearance(self.robot.outline(), self.params.body_clearance)
        self.min_clearance = min(self.min_clearance, c)

    def run(self) -> Result:
        dur = self.scenario.duration
        self._schedule_faults()
        for proc in self.nodes.values():
            proc.start()
            if proc.tick_period:
                self._every(proc.tick_period, lambda t, p=proc: p.tick(t) if p.alive else None)
        self._every(self.params.dt, self._physics)
        self._every(POSE_SAMPLE_S, self._sample)
        self._every(CLEARANCE_SAMPLE_S, self._clearance)
        self.sched.run_until(dur)
        from sim2d.metrics import build_metrics
        metrics = build_metrics(self)
        return Result(self.scenario, self.verdict, self.frames, self.poses, metrics, metrics["trace_hash"],
                      self.sensors, self.world, self.robot, self.snapshots)


def trace_lines(frames: list[TraceEntry], spec: Any, codec: Codec) -> list[str]:
    """One tab-separated line per frame: start, end, bus, sender, src, dst, message, bytes, flags."""
    def name(addr: int | None) -> str:
        if addr is None:
            return "?"
        if addr == spec.broadcast:
            return "ALL"
        n = spec.node_at(addr)
        return n.short if n else f"0x{addr:02X}"
    out = []
    for f in frames:
        data = f.heard if f.heard is not None else f.sent
        d = codec.decode(data)
        msg = codec.describe(data) if d is not None else "<undecodable>"
        out.append(f"{f.start:.6f}\t{f.end:.6f}\t{f.bus}\t{f.sender}\t{name(d.src if d else None)}\t"
                   f"{name(d.dst if d else None)}\t{msg}\t{data.hex()}\t{','.join(f.flags)}")
    return out


def trace_hash(frames: list[TraceEntry], poses: list[tuple[float, float, float, float]]) -> str:
    """SHA-256 over every frame (times, bus, sender, bytes sent and heard, flags) and the pose log."""
    h = hashlib.sha256()
    for f in frames:
        h.update(f"{f.start:.9f} {f.end:.9f} {f.bus} {f.sender} {f.sent.hex()} "
                 f"{f.heard.hex() if f.heard is not None else '-'} {','.join(f.flags)}\n".encode())
    for t, x, y, th in poses:
        h.update(f"{t:.3f} {x:.9f} {y:.9f} {th:.9f}\n".encode())
    return h.hexdigest()
