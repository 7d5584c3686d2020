"""The simulation: world, robot, sensors, buses and the 39 nodes on one clock.

Every node is its behaviour class (behaviours/, a subclass of the generated
skeleton) on a simulated board (sim2d.hardware). Nodes exchange BYTES: a
node's skeleton frames a message with the generated codec and hands the
bytes to its bus port; the bus delivers bytes to every station, whose
skeleton parses them (arachnae_proto.frame). One discrete-event scheduler
drives everything: the physics step is a periodic event (fixed dt), bus
frames are events at their start and end, node timers are events. Nothing
is stepped per bit or per byte.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Any, Callable

from arachnae_proto.messages import BY_NAME as MESSAGES
from arachnae_proto.network import BROADCAST

from behaviours import behaviour_class
from captures.pcapng import CapturedFrame
from behaviours.netconfig import Config, NetConfig
from behaviours.post import Verdict
from behaviours.runtime import Runtime, line_check
from sim2d.bus import Bus, Fault as BusFault, TraceEntry
from sim2d.events import Scheduler
from sim2d.geometry import point_in_polygon
from sim2d.hardware import NodeHardware
from sim2d.level0_io import Microphones, RcpLine, schedule as schedule_level0_io
from sim2d.rng import stream
from sim2d.robot import Robot
from sim2d.robot_params import DEFAULT, RobotParams
from sim2d.scenario import Scenario
from sim2d.sensors import Sensors
from sim2d.world import World
from tracecheck.trace import trace_lines

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
    nodes: dict = field(default_factory=dict)      # short name -> node (for its debug-port artifacts)
    notes: list = field(default_factory=list)      # debug-port notes: (t, node, event, data)
    trace_rows: list[str] | None = None            # trace.tsv's rows (Simulation.trace_rows); None: not made


def _receiver(node: Runtime, hw: NodeHardware) -> Any:
    """The node's UART: every frame on the bus reaches the skeleton's receive(), which parses it.

    Shortcut, same outcome: a frame that is intact and addressed to another node
    is dropped here instead of inside receive() (which ignores it silently).
    """
    own = node.address
    receive = node.receive
    heard = getattr(node, "on_line_frame", None)      # the UART hears every frame on the line

    def deliver(bus: str, t: float, data: bytes) -> None:
        if not hw.alive:
            return
        if heard is not None:
            heard(bus, data)
        if data and data[0] != own and data[0] != BROADCAST and line_check(data) is not None:
            return
        receive(bus, data)              # ours, broadcast, or bad: the skeleton parses (and reports) it
    return deliver


def _echo(node: Runtime, hw: NodeHardware) -> Any:
    def echo(bus: str, t: float, sent: bytes, heard: bytes) -> None:
        if hw.alive:
            node.on_echo(bus, sent, heard)
    return echo


NodeFactory = Callable[..., Any]   # (address, transmit, hw, config) -> a node that takes receive(bus, data)


class Simulation:
    def __init__(self, scenario: Scenario, spec: Any, params: RobotParams = DEFAULT, keep_frames_every: float | None = None,
                 replace_nodes: dict[str, NodeFactory] | None = None):
        """`replace_nodes` runs some nodes as something else than their Python behaviour, e.g. firmware
        in simavr (`--sil`); such a node's UART hears every frame on its buses."""
        if scenario.battery_ah is not None:           # the scenario's own battery (3.2.17 under-voltage)
            params = replace(params, battery_ah=scenario.battery_ah)
        self.scenario, self.spec, self.params = scenario, spec, params
        replace_nodes = replace_nodes or {}
        self.sched = Scheduler()
        self.world = World(scenario)
        self.robot = Robot(params, self.world, scenario.start)
        self.robot.charge_used_ah = (1.0 - scenario.battery_charge) * params.battery_ah
        self.sensors = Sensors(self.world, self.robot, scenario.seed)
        self.rcp = RcpLine()                                   # the UIC/RCP's RS-232 line (seed 4.1)
        self.microphones = Microphones(scenario.seed)          # the APU/SDF's view of `sounds:` (seed 3.2.7)
        self.frames: list[FrameRecord] = []
        self.buses: dict[str, Bus] = {}
        for name, b in spec.buses.items():
            # spec buses: no frame starts before the line was idle for the frame gap (turnaround, idle gap)
            self.buses[name] = Bus(name, self.sched, b.baud, b.bits_per_char, b.frame_gap_us * 1e-6,
                                   stream(scenario.seed, f"bus:{name}"), self._trace)
        net = NetConfig.from_spec(spec)
        if scenario.arbitration:       # a replay of the checker's seed variant runs the seed's rule on that bus
            seed = {b: "seed" for b, v in scenario.arbitration.items() if v == "seed"}
            net = replace(net, arbitration={**net.arbitration, **seed})
        self.config = Config(net, geometry=params, task=scenario.task)
        self.nodes: dict[str, Runtime] = {}
        self.hardware: dict[str, NodeHardware] = {}
        self.verdict: Verdict | None = None
        self.verdict_time: float | None = None
        self.post_reports: dict[str, tuple[float, list[int]]] = {}
        self.moves: list[tuple[float, int]] = []
        self.stimuli: list[tuple[float, str]] = []
        self.escapes: list[tuple[float, float]] = []
        self.events: list[tuple[float, str, int]] = []
        self.notes: list[tuple[float, str, str, dict[str, Any]]] = []   # every debug-port note: t, node, event, data
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
        self._trace_rows: list[str] | None = None
        absent = set(scenario.absent)
        for n in spec.nodes:
            if n.short in absent:
                continue
            hw = NodeHardware(self, n)
            factory = replace_nodes.get(n.short)
            if factory is None:
                proc = behaviour_class(n.role)(n.address, hw.transmit, hw, self.config)
                receive = _receiver(proc, hw)
            else:
                proc = factory(n.address, hw.transmit, hw, self.config)
                receive = (lambda p: lambda bus, t, data: p.receive(bus, data))(proc)
            self.nodes[n.short], self.hardware[n.short] = proc, hw
            for bus in (n.bus, n.masters):
                if bus is not None:
                    hw.ports[bus] = self.buses[bus].attach(n.short, receive, _echo(proc, hw))
        # a JAC that is absent, or whose LCP is, never gets a set-point: its servo is limp (CHOICE)
        for n in spec.role_nodes("JAC"):
            lcp = next(m for m in spec.role_nodes("LCP") if m.leg == n.leg)
            if n.short in absent or lcp.short in absent:
                self.robot.legs[n.leg].joints[n.joint - 1].powered = False

    # --- trace and telemetry ------------------------------------------------------
    def _trace(self, e: TraceEntry) -> None:
        self.frames.append(e)      # decoded only when written: the bytes determine the text

    def trace_rows(self) -> list[str]:
        """trace.tsv's rows (tracecheck.trace.trace_lines) of the finished run, made once: the protocol
        metrics read them and write_outputs writes them (decoding every frame twice took ~15 % of a run)."""
        if self._trace_rows is None:
            self._trace_rows = trace_lines(self.frames, self.notes)
        return self._trace_rows

    def on_note(self, node: Any, event: str, data: dict[str, Any]) -> None:
        """A node's debug-port telemetry (behaviours.hardware.Hardware.note) into the metrics."""
        t = self.sched.now
        self.notes.append((t, node.short, event, data))
        if event == "post_verdict":
            self.verdict, self.verdict_time = data["verdict"], t
        elif event == "post_report":
            self.post_reports[node.short] = (t, list(data["missing"]))
        elif event == "move":
            self.moves.append((t, data["mov_cmd"]))
        elif event == "stimulus":
            self.stimuli.append((t, data.get("kind", "")))
            c = self.scenario.contention
            if c is not None and data.get("kind") == c.stimulus:
                self._contend(c.bus, node)
        elif event == "escape":
            self.escapes.append((data["start"], data["end"]))
        elif event in ("pit", "blocked"):
            self.events.append((t, event, data.get("leg", 0)))

    def _contend(self, bus: str, source: Any) -> None:
        """scenario `contention`: every other requesting slave of `bus` asks for the line now (worst case, 5.2)."""
        for a in self.config.net.requesters.get(bus, ()):
            short = self.spec.node_at(a).short
            proc, hw = self.nodes.get(short), self.hardware.get(short)
            announce = getattr(proc, "announce", None)
            if proc is not source and announce is not None and hw is not None and hw.alive:
                announce(force=True)

    # --- faults --------------------------------------------------------------------
    def _schedule_faults(self) -> None:
        for f in self.scenario.faults:
            self.sched.at(f.at, self._fault_note, f)
            if f.kind == "sensor":
                self.sched.at(f.at, self.sensors.set_fault, f.node, f.noise)
                if f.until is not None:
                    self.sched.at(f.until, self.sensors.set_fault, f.node, 0.0)
            elif f.kind == "request":
                self.sched.at(f.at, self._request, f.node)
            elif f.kind == "collide":
                bus = self.spec.node(f.node).bus
                self.sched.at(f.at, self._set_deaf, bus, frozenset(f.nodes))
                if f.until is not None:
                    self.sched.at(f.until, self._set_deaf, bus, frozenset())
            elif f.kind == "bus":
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

    def _fault_note(self, f: Any) -> None:
        """The fault's start in the notes (metrics notes.fault_injected: what happened after it)."""
        self.notes.append((self.sched.now, "sim", "fault_injected", {"kind": f.kind, "node": f.node, "bus": f.bus}))

    def _request(self, short: str) -> None:
        """The node asks for its bus (its request_message to its master), as when a record becomes pending."""
        node, n = self.nodes.get(short), self.spec.node(short)
        if node is None or not self.hardware[short].alive:
            return
        b = self.spec.buses[n.bus]
        node.slave_send(self.spec.node(b.master).address, MESSAGES[b.request_message]())

    def _set_deaf(self, bus: str, nodes: frozenset[str]) -> None:
        b = self.buses[bus]
        b.deaf, b.deaf_opcode = nodes, MESSAGES[self.spec.buses[bus].request_message].OPCODE

    def _set_bus_fault(self, bus: str, fault: BusFault) -> None:
        self.buses[bus].fault = fault

    def _kill(self, short: str) -> None:
        hw = self.hardware[short]
        hw.alive = False
        for port in hw.ports.values():
            port.killed = True
            port.queue.clear()
        if hw.joint is not None:
            # a dead JAC sends no more pulses: the hobby servo goes limp (CHOICE)
            self.robot.legs[hw.leg].joints[hw.joint - 1].powered = False
        self.events.append((self.sched.now, "kill", 0))

    def _mute(self, short: str, on: bool) -> None:
        for port in self.hardware[short].ports.values():
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
        schedule_level0_io(self)            # operator keys, sound events
        for proc in self.nodes.values():
            proc.start()                    # power-on: behaviours start their own timers
        self._every(self.params.dt, self._physics)
        self._every(POSE_SAMPLE_S, self._sample)
        self._every(CLEARANCE_SAMPLE_S, self._clearance)
        self.sched.run_until(dur)
        from sim2d.metrics import build_metrics
        metrics = build_metrics(self)
        return Result(self.scenario, self.verdict, self.frames, self.poses, metrics, metrics["trace_hash"],
                      self.sensors, self.world, self.robot, self.snapshots, self.nodes, self.notes, self.trace_rows())


def capture_frames(frames: list[TraceEntry]) -> list[CapturedFrame]:
    """The frames as a tap on each bus saw them (bus.pcapng), in order of their start.

    Like trace_lines, a frame's bytes are what the receivers heard, or what was
    sent when no receiver got it (an injected loss); the marks travel along.
    """
    out = [CapturedFrame(f.bus, round(f.start * 1e9), f.heard if f.heard is not None else f.sent, f.flags, f.sender, f.sent)
           for f in frames]
    out.sort(key=lambda c: c.time_ns)
    return out
