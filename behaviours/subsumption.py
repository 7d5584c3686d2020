"""Brooks' subsumption architecture (seed reference [12], docs/decisions.md D8) as a small library.

Why explicit wiring instead of an if-chain: the seed wants fast reactions on
low system levels that interrupt navigation (5.2) and a software that is easy
to extend (5.1.3). Here every behaviour is a module with named input and
output ports, and who may override whom is *declared* data:

  - a wire carries messages from an output port (or a sensor) to an input port
    (or an actuator);
  - a suppressor sits on an input: a message from its source REPLACES what
    arrives on that input, and for `hold_s` seconds after the source's last
    message the ordinary wire is cut (Brooks' suppressor with its time constant);
  - an inhibitor sits on an output: a message from its source BLOCKS that
    output for `hold_s` seconds after the source's last message.

Modules are evaluated once per `step()` in dependency order, so a reflex that
fires in a step pre-empts the task in that same step (5.2: react within about
1 s). Every delivery to an actuator is recorded in a `ControlTrace`: which
layer held the actuator (for the NP3: the MOVE command to the MMC) and for how
long. Pure logic: the clock is injected, nothing here imports the simulator.

The NP3's own network (reflexes, avoidance, task) is declared in
behaviours.np3_layers. The seed puts the fast reactions on the lowest level
and lets them interrupt navigation (5.2), so the suppression wires run from
the reflexes towards the task; the mechanism is Brooks', only the direction
of the wires is the seed's.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable, Mapping, Protocol

Clock = Callable[[], float]
Outputs = Mapping[str, Any]

NONE_LAYER = "(none)"   # trace name while no module has driven an actuator yet


# --------------------------------------------------------------------------- modules
class Behaviour(Protocol):
    """A module: reads its input registers, may emit one message per output port."""

    name: str
    layer: str
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]

    def step(self, inputs: Mapping[str, Any], now: float) -> Outputs:
        """Return {output port: message}; a port missing or None sends nothing this step."""


@dataclass
class FunctionModule:
    """A stateless module made from a function of its inputs (and the time)."""

    name: str
    layer: str
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    fn: Callable[[Mapping[str, Any], float], Outputs]

    def step(self, inputs: Mapping[str, Any], now: float) -> Outputs:
        return self.fn(inputs, now)


@dataclass
class Plan:
    """A timed sequence of commands (an augmented FSM's timer states): [(duration s, value), ...]."""

    steps: list[tuple[float, Any]]
    started: float

    def value(self, now: float) -> Any | None:
        t = self.started
        for duration, value in self.steps:
            t += duration
            if now < t:
                return value
        return None


class ReflexModule:
    """A reflex: a trigger function starts a timed plan of commands; it emits only while the plan runs.

    While the plan runs, new triggers do not restart it (the reflex finishes
    its manoeuvre); after it ends a still-present trigger starts it again.
    The trigger gets the input registers and the time.
    """

    def __init__(self, name: str, layer: str, inputs: tuple[str, ...],
                 trigger: Callable[[Mapping[str, Any], float], list[tuple[float, Any]] | None],
                 output: str = "move") -> None:
        self.name, self.layer, self.inputs, self.outputs = name, layer, inputs, (output,)
        self.trigger = trigger
        self.plan: Plan | None = None

    def step(self, inputs: Mapping[str, Any], now: float) -> Outputs:
        if self.plan is not None and self.plan.value(now) is None:
            self.plan = None
        if self.plan is None:
            steps = self.trigger(inputs, now)
            if steps:
                self.plan = Plan(steps, now)
        value = self.plan.value(now) if self.plan else None
        return {self.outputs[0]: value}


# --------------------------------------------------------------------------- wiring
@dataclass
class _Node:
    """A suppressor (on an input) or an inhibitor (on an output) with Brooks' time constant."""

    kind: str             # "suppress" | "inhibit"
    source: str           # "module.port"
    target: str           # "module.port" or "actuator.name"
    hold_s: float
    last: float = -math.inf

    def active(self, now: float) -> bool:
        return now < self.last + self.hold_s


@dataclass(frozen=True)
class Interval:
    """One stretch of time during which one module (of one layer) held an actuator."""

    start: float
    end: float
    layer: str
    module: str

    @property
    def duration(self) -> float:
        return self.end - self.start


class ControlTrace:
    """Who drove an actuator and when: closed intervals plus the one still open."""

    def __init__(self, actuator: str, start: float) -> None:
        self.actuator = actuator
        self.start = start
        self.closed: list[Interval] = []
        self.current = (start, NONE_LAYER, NONE_LAYER)   # (since, layer, module)
        self.last_time = start

    def record(self, now: float, layer: str, module: str) -> None:
        since, cur_layer, cur_module = self.current
        if (layer, module) != (cur_layer, cur_module):
            if now > since:
                self.closed.append(Interval(since, now, cur_layer, cur_module))
            self.current = (now, layer, module)
        self.last_time = max(self.last_time, now)

    def advance(self, now: float) -> None:
        self.last_time = max(self.last_time, now)

    def intervals(self, until: float | None = None) -> list[Interval]:
        """Closed intervals plus the open one up to `until` (default: the last step's time)."""
        end = self.last_time if until is None else until
        since, layer, module = self.current
        tail = [Interval(since, end, layer, module)] if end > since else []
        return self.closed + tail

    def summary(self, until: float | None = None) -> dict[str, float]:
        """Seconds of control per layer, in order of first appearance."""
        out: dict[str, float] = {}
        for iv in self.intervals(until):
            out[iv.layer] = out.get(iv.layer, 0.0) + iv.duration
        return out

    def switches(self, until: float | None = None) -> int:
        """How often control passed from one layer to another."""
        ivs = self.intervals(until)
        return sum(1 for a, b in zip(ivs, ivs[1:]) if a.layer != b.layer)

    def table(self, until: float | None = None) -> str:
        rows = [f"{'start s':>9} {'end s':>9} {'layer':<12} module"]
        rows += [f"{iv.start:9.2f} {iv.end:9.2f} {iv.layer:<12} {iv.module}" for iv in self.intervals(until)]
        return "\n".join(rows)


class Network:
    """Modules, sensors, actuators and the declared wires, suppressors and inhibitors between them.

    Port names are "module.port"; sensors are "sensor.NAME" and actuators
    "actuator.NAME". Declaration order matters only where Brooks' diagrams
    would show it: several suppressors on one input are nested, the one
    declared last sitting closest to the input (it wins).
    """

    def __init__(self, clock: Clock) -> None:
        self.clock = clock
        self.modules: dict[str, Behaviour] = {}
        self.sensors: dict[str, Any] = {}
        self.actuators: dict[str, Any] = {}
        self.wires: list[tuple[str, str]] = []
        self.nodes: list[_Node] = []
        self.registers: dict[str, Any] = {}          # last message on each module input
        self.traces: dict[str, ControlTrace] = {}
        self.delivered: dict[str, str | None] = {}    # actuator -> port whose message reached it in the last step
        self.order: list[str] | None = None

    # -- declaration -----------------------------------------------------------------
    def add(self, module: Behaviour) -> Behaviour:
        if module.name in self.modules:
            raise ValueError(f"module {module.name!r} declared twice")
        self.modules[module.name] = module
        self.order = None
        return module

    def actuator(self, name: str) -> str:
        self.actuators.setdefault(name, None)
        return f"actuator.{name}"

    def wire(self, source: str, target: str) -> None:
        """An ordinary wire: source output (or sensor) -> target input (or actuator)."""
        self._check_source(source)
        self._check_target(target)
        if any(t == target for _s, t in self.wires):
            raise ValueError(f"{target} already has a wire; use suppress() to override it")
        self.wires.append((source, target))
        self.order = None

    def suppress(self, source: str, target: str, hold_s: float) -> None:
        """`source` replaces what arrives on input `target`; the wire stays cut `hold_s` after its last message."""
        self._check_source(source, sensor_ok=False)
        self._check_target(target)
        self.nodes.append(_Node("suppress", source, target, hold_s))
        self.order = None

    def inhibit(self, source: str, target: str, hold_s: float) -> None:
        """`source` blocks output `target` for `hold_s` after its last message."""
        self._check_source(source, sensor_ok=False)
        self._check_source(target, sensor_ok=False)
        self.nodes.append(_Node("inhibit", source, target, hold_s))
        self.order = None

    def _check_source(self, port: str, sensor_ok: bool = True) -> None:
        owner, _, name = port.partition(".")
        if owner == "sensor" and sensor_ok:
            return
        if owner not in self.modules or name not in self.modules[owner].outputs:
            raise ValueError(f"{port}: no such output")

    def _check_target(self, port: str) -> None:
        owner, _, name = port.partition(".")
        if owner == "actuator":
            self.actuator(name)
            return
        if owner not in self.modules or name not in self.modules[owner].inputs:
            raise ValueError(f"{port}: no such input")

    def wiring_table(self) -> str:
        """The declared wiring, one row per wire / suppressor / inhibitor."""
        rows = [("kind", "from", "to", "hold s")]
        rows += [("wire", s, t, "-") for s, t in self.wires]
        rows += [(n.kind, n.source, n.target, f"{n.hold_s:g}") for n in self.nodes]
        widths = [max(len(r[i]) for r in rows) for i in range(4)]
        lines = ["  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip() for r in rows]
        lines.insert(1, "  ".join("-" * w for w in widths))
        return "\n".join(lines)

    # -- evaluation -------------------------------------------------------------------
    def evaluation_order(self) -> list[str]:
        """Modules after everything that feeds, suppresses or inhibits their inputs (declaration order breaks ties)."""
        if self.order is not None:
            return self.order
        deps: dict[str, set[str]] = {m: set() for m in self.modules}

        def owner(port: str) -> str | None:
            o = port.partition(".")[0]
            return o if o in self.modules else None

        for s, t in self.wires:
            src, dst = owner(s), owner(t)
            if src and dst:
                deps[dst].add(src)
                for n in self.nodes:       # an inhibitor on the wire's source gates this delivery
                    if n.kind == "inhibit" and n.target == s and owner(n.source):
                        deps[dst].add(owner(n.source))
        for n in self.nodes:
            dst = owner(n.target)
            if n.kind == "suppress" and dst and owner(n.source):
                deps[dst].add(owner(n.source))
        order: list[str] = []
        pending = list(self.modules)
        while pending:
            ready = [m for m in pending if deps[m] <= set(order)]
            if not ready:
                raise ValueError(f"wiring has a cycle among {sorted(pending)}")
            order.append(ready[0])
            pending.remove(ready[0])
        self.order = order
        return order

    def sense(self, **values: Any) -> None:
        """Set sensor values (they stay until set again)."""
        self.sensors.update(values)

    def step(self) -> dict[str, Any]:
        """Evaluate every module once; return the actuators' values after this step."""
        now = self.clock()
        for trace in self.traces.values():
            trace.advance(now)
        emitted: dict[str, Any] = {}                      # "module.port" -> message sent this step
        for name in self.evaluation_order():
            module = self.modules[name]
            inputs = {p: self._deliver(f"{name}.{p}", emitted, now) for p in module.inputs}
            for p, v in inputs.items():
                if v is not None:
                    self.registers[f"{name}.{p}"] = v[0]
            regs = {p: self.registers.get(f"{name}.{p}") for p in module.inputs}
            for port, value in (module.step(regs, now) or {}).items():
                if value is not None:
                    emitted[f"{name}.{port}"] = value
            for n in self.nodes:                       # an inhibitor's timer restarts with each message
                if n.kind == "inhibit" and n.source.partition(".")[0] == name and n.source in emitted:
                    n.last = now
        for act in self.actuators:
            got = self._deliver(f"actuator.{act}", emitted, now)
            trace = self.traces.setdefault(act, ControlTrace(act, now))
            self.delivered[act] = got[1] if got is not None else None
            if got is not None:
                value, src = got
                self.actuators[act] = value
                mod = src.partition(".")[0]
                trace.record(now, self.modules[mod].layer if mod in self.modules else "sensor", mod)
        return dict(self.actuators)

    def _deliver(self, target: str, emitted: Mapping[str, Any], now: float) -> tuple[Any, str] | None:
        """The message reaching `target` this step, with the port it came from, or None."""
        got: tuple[Any, str] | None = None
        for s, t in self.wires:
            if t == target:
                if s.startswith("sensor."):          # a sensor's register follows the sensor
                    got = (self.sensors.get(s.partition(".")[2]), s)
                elif s in emitted and not self._inhibited(s, now):
                    got = (emitted[s], s)
        for n in self.nodes:                       # nested suppressors, innermost (last declared) wins
            if n.kind == "suppress" and n.target == target:
                if n.source in emitted and not self._inhibited(n.source, now):
                    got = (emitted[n.source], n.source)
                    n.last = now                   # a suppressor's timer restarts with each message it passes
                elif n.active(now):
                    got = None
        return got

    def _inhibited(self, port: str, now: float) -> bool:
        return any(n.kind == "inhibit" and n.target == port and n.active(now) for n in self.nodes)

    def trace(self, actuator: str = "move") -> ControlTrace:
        return self.traces[actuator]


__all__ = [
    "Behaviour", "FunctionModule", "ReflexModule", "Plan", "Network", "ControlTrace", "Interval",
    "NONE_LAYER",
]
