"""Hold a bus trace to the verified protocol: the rules come from the models, not from here.

What is checked, and where each rule comes from:
- one talker per bus (seed 3.2.2), except the collisions the models permit:
  requests of contending slaves started in the same slot (arbitration model)
  and a late reply meeting the master's next frame (id_retry model: a loss);
- after a corrupt frame every request starts only when the arbitration
  model's own send guard (`arbitration.send_guard`, evaluated on the slot
  position read off the trace) allows it;
- every request is served within the bound K the checker proves for its bus
  (tracecheck.bounds); the master's own transactions, which the model leaves
  out, do not count towards the wait;
- ID_REQ (seed 3.2.2): no resend before the response timeout to the first
  byte (spec_adapter), a reply begun in time is waited for, exactly
  id_retries resends, then the node counts as inactive;
- the POST verdict (seed 6.3) is the POST model's own oracle
  (`post.expected_verdict`) over the nodes that answered on the wire;
- MOVE_RELAYED resends follow protocol.move_retries; INIT is broadcast once
  after each POST that did not halt (seed 3.2.3); every record that reaches
  the MCP is relayed to its target (seed 3.2.2: every datum runs through it);
- the reflex rate that bounds the arbitration model's lead (spec reflexes.
  min_interval_ms, `ArbParams.reflex_gap_ms`): the source's `reflex_raised`
  debug notes (when it raised the request; the line shows only when the
  request got on it) at least min_interval apart. A trace without those notes
  (a capture has no debug port) says the check was skipped (`skipped` in the
  report and a line of `arachnae trace check`), never passes it silently.
A violation names the first offending frame by time, bus and trace line.
"""
from __future__ import annotations

from bisect import bisect_left, bisect_right
from collections import defaultdict
from dataclasses import dataclass, field
from typing import Any

from arachnae_proto import messages as M
from arachnae_proto.enums import Gait
from arachnae_proto.network import BROADCAST

from model_check import expr, spec_adapter
from model_check.models import arbitration, post as post_model
from tracecheck.bounds import BusBound, bounds
from tracecheck.trace import LIST_SEP, Trace, TraceFrame, TraceNote

EPS = 1e-7                   # seconds: the trace's resolution is 1 us
GAITS = frozenset(int(g) for g in Gait)


@dataclass(frozen=True)
class Violation:
    t: float
    bus: str
    line: int
    rule: str
    text: str

    def __str__(self) -> str:
        return f"{self.t:.6f} s bus {self.bus} (trace line {self.line}): {self.rule}: {self.text}"


@dataclass
class Report:
    violations: list[Violation] = field(default_factory=list)
    requests: int = 0          # request episodes seen on contended buses
    served: int = 0
    declined: int = 0          # got through, the master chose not to fetch (e.g. seed 6.2: untrusted data)
    unchecked: int = 0         # met line noise or a lost frame: the model's bound does not apply
    starved: int = 0           # waited longer than the spec variant's K (also under the seed variant)
    max_wait_slots: dict[str, float] = field(default_factory=dict)
    k_slots: dict[str, int | None] = field(default_factory=dict)
    checked: dict[str, int] = field(default_factory=lambda: defaultdict(int))
    skipped: dict[str, str] = field(default_factory=dict)    # rule -> why it could not be checked on this trace

    def add(self, f: TraceFrame | None, rule: str, text: str, t: float | None = None, bus: str | None = None,
            line: int | None = None) -> None:
        """A violation at frame f, or (f None) at time t on `bus`, trace line `line` (a debug row)."""
        self.violations.append(Violation(f.start if t is None else t, f.bus if bus is None else bus,
                                         line if line is not None else f.line if f is not None else 0, rule, text))

    def metrics(self) -> dict[str, Any]:
        first = min(self.violations, key=lambda v: (v.t, v.line)) if self.violations else None
        by_rule: dict[str, int] = defaultdict(int)
        for v in self.violations:
            by_rule[v.rule] += 1
        return {"violations": len(self.violations), "first": str(first) if first else None,
                "by_rule": dict(sorted(by_rule.items())), "requests": self.requests, "served": self.served,
                "declined": self.declined, "unchecked": self.unchecked, "starved": self.starved,
                "max_wait_slots": {b: round(v, 2) for b, v in sorted(self.max_wait_slots.items())},
                "k_slots": dict(sorted(self.k_slots.items())), "checked": dict(sorted(self.checked.items())),
                "skipped": dict(sorted(self.skipped.items()))}


@dataclass
class BusRules:
    """One bus's rules, every number from the spec through model_check.spec_adapter."""

    name: str
    master: str
    gap_s: float
    bit_s: float
    timeout_s: float               # seed 3.2.2: to the first byte (or the last, protocol.response_timeout_to)
    id_retries: int
    arb: spec_adapter.ArbParams | None = None
    request: str | None = None
    bound: BusBound | None = None
    guards: dict[str, Any] = field(default_factory=dict)      # slave -> compiled send guard
    fetch: dict[str, tuple[list[str], list[str], str]] = field(default_factory=dict)

    @property
    def slot_s(self) -> float:
        return self.arb.slot_us * 1e-6 if self.arb else 0.0

    @property
    def window(self) -> int:
        return arbitration.window_slots(self.arb, len(self.arb.slaves)) if self.arb else 0


class Rules:
    """The spec's protocol rules for every bus, built once per spec (and arbitration variant per bus)."""

    def __init__(self, spec: Any, variants: dict[str, str] | None = None) -> None:
        self.spec = spec
        self.variants = variants or {}
        self.short = {n.address: n.short for n in spec.nodes}
        self.node = {n.short: n for n in spec.nodes}
        self.mcp = next(n.short for n in spec.nodes if n.bus is None)
        self.move_retries = int(spec.protocol.move_retries)
        self.defer_slots = int(spec.protocol.master_defer_slots)
        self.inactive = set(spec.post.inactive_statuses)
        # seed 3.2.3: each role's STATUS_ACK form, found by attribute (spec messages.<m>.reply_to), not by name
        self.status_acks = {m.name for m in spec.messages if m.reply_to == "STATUS_REQ"}
        # seed 3.2.2: the records the MCP relays (spec messages.<m>.record, relayed_as), found by attribute, not name:
        # a record naming its `target` goes there as its relayed_as; the others (MOVE) to that message's receiver
        relays = {m.name: m.relayed_as for m in spec.messages if m.record and m.relayed_as}
        self.targeted = {r: d for r, d in relays.items() if any(f.name == "target" for f in spec.message(r).fields)}
        self.command_relays: dict[str, set[str]] = {}
        for r, d in relays.items():
            if r not in self.targeted:
                self.command_relays.setdefault(d, set()).add(r)
        self.post = spec_adapter.post(spec)
        self.tree = post_model.Tree(self.post, None)
        proved = bounds(spec)
        self.buses: dict[str, BusRules] = {}
        for name, b in spec.buses.items():
            r = BusRules(name, b.master, b.frame_gap_us * 1e-6, 1.0 / b.baud,
                         spec_adapter.first_byte_timeout_us(spec, name) * 1e-6, b.id_retries)
            if b.arbitration != "polled":
                variant = self.variants.get(name, "spec")
                r.arb, r.request, r.bound = spec_adapter.arbitration(spec, name), b.request_message, proved.get(name)
                n = len(r.arb.slaves)
                for i, s in enumerate(r.arb.slaves):
                    # the model's own guard for this slave's request, evaluated on values read off the trace
                    text = arbitration.send_guard(r.arb, variant, i, s.rank, n)
                    code = compile(expr.to_python(text, lambda v: f"v[{v!r}]"), f"<send {s.short}>", "eval")
                    r.guards[s.short] = (code, i, s.rank)
                    r.fetch[s.short] = spec_adapter.record_route(spec, name, spec.node(s.short))
            self.buses[name] = r


def heard_corrupt(f: TraceFrame) -> bool:
    """Heard corrupt on the line (by every station, the sender's echo included), not lost."""
    return f.heard is not None and not f.intact


def _src(rules: Rules, f: TraceFrame) -> str | None:
    return rules.short.get(f.parsed.src) if f.parsed is not None else (f.sender or None)


def _dst(rules: Rules, f: TraceFrame) -> str | None:
    if f.parsed is None:
        return None
    return "*" if f.parsed.dst == BROADCAST else rules.short.get(f.parsed.dst)


class Validator:
    def __init__(self, trace: Trace, rules: Rules, timed: bool = True) -> None:
        self.trace, self.rules, self.timed = trace, rules, timed
        self.report = Report()
        self.by_bus: dict[str, list[TraceFrame]] = defaultdict(list)
        for f in trace.frames:
            self.by_bus[f.bus].append(f)
        self.end_t = max((f.end for f in trace.frames), default=0.0)
        self.corrupt: dict[str, list[TraceFrame]] = {}      # per bus: frames that end a window (heard corrupt)
        self.collided: set[int] = set()                      # lines of frames that overlapped another

    # -- helpers --------------------------------------------------------------------------
    def src(self, f: TraceFrame) -> str | None:
        return _src(self.rules, f)

    def dst(self, f: TraceFrame) -> str | None:
        return _dst(self.rules, f)

    def is_request(self, r: BusRules, f: TraceFrame) -> bool:
        return r.request is not None and f.name == r.request and self.src(f) in r.guards

    def run(self) -> Report:
        for bus, frames in self.by_bus.items():
            r = self.rules.buses.get(bus)
            if r is None:
                continue
            if self.timed:
                self.one_talker(r, frames)
            else:                    # untimed: frames as they came, one after another
                self.corrupt[bus] = [f for f in frames if heard_corrupt(f)]
            self.id_exchanges(r, frames)
            if r.arb is not None and self.timed:
                self.arbitration(r, frames)
        self.post_verdicts()
        self.first_bus_relays()
        if self.timed:
            self.reflex_rate()
        self.report.violations.sort(key=lambda v: (v.t, v.line))
        return self.report

    # -- one talker ----------------------------------------------------------------------------
    def one_talker(self, r: BusRules, frames: list[TraceFrame]) -> None:
        """seed 3.2.2: one talker; overlapping frames only as the models permit."""
        self.report.checked["one_talker"] += len(frames)
        clusters: list[list[TraceFrame]] = []
        end = -1.0
        for f in frames:
            if clusters and f.start < end - EPS:
                clusters[-1].append(f)
            else:
                clusters.append([f])
            end = max(end, f.end) if clusters[-1] and len(clusters[-1]) > 1 else f.end
        last_to: dict[str, tuple[float, ...]] = {}   # slave -> ends of the master's last two frames to it
        corrupt: list[TraceFrame] = []
        for c in clusters:
            if len(c) == 1:
                f = c[0]
                if heard_corrupt(f):
                    corrupt.append(f)        # line noise: every station hears a corrupt frame
            else:
                self.collided.update(f.line for f in c)
                corrupt.append(max(c, key=lambda f: f.end))
                self._collision(r, c, last_to)
            for f in c:
                if self.src(f) == r.master and f.parsed is not None:
                    last_to[self.dst(f) or "*"] = (last_to.get(self.dst(f) or "*", ()) + (f.end,))[-2:]
        self.corrupt[r.name] = corrupt

    def _collision(self, r: BusRules, c: list[TraceFrame], last_to: dict[str, float]) -> None:
        if all(self.is_request(r, f) for f in c):
            if max(f.start for f in c) - min(f.start for f in c) < r.slot_s:
                return               # arbitration model: requests started in the same slot collide
            late = max(c, key=lambda f: f.start)
            self.report.add(late, "one_talker", f"{self.src(late)}'s {late.name} started "
                            f"{(late.start - c[0].start) * 1e3:.2f} ms into another request (carrier sense)")
            return
        masters = [f for f in c if self.src(f) == r.master]
        others = [f for f in c if self.src(f) != r.master]
        if len(masters) == 1 and all(self.is_request(r, f) for f in others):
            # the master's frames are outside the arbitration model (its environment): a request meeting
            # one is corrupted like a collision, and the backoff_slot check holds the slaves to the window
            return
        if len(masters) <= 1 and others:
            stale = [f for f in others if not self.is_request(r, f) and self._stale(r, f, last_to)]
            if len(stale) == len(others):
                return               # id_retry model: a late or second answer meets the master's next frame (a loss)
        second = sorted(c, key=lambda f: (f.start, f.line))[1]
        names = ", ".join(f"{self.src(f) or f.sender}'s {f.name}" for f in c)
        self.report.add(second, "one_talker", f"two talkers on the line: {names}")

    def _stale(self, r: BusRules, f: TraceFrame, last_to: dict[str, tuple[float, ...]]) -> bool:
        """A reply the master no longer waits for (id_retry model): begun after the response timeout, or
        the second answer of a node asked twice whose first answer came in between."""
        who = self.src(f) or "?"
        asked = last_to.get(who)
        if asked is None:
            return False             # never asked: a slave talking on its own is no reply at all
        if f.start > asked[-1] + r.timeout_s - EPS:
            return True
        return len(asked) >= 2 and any(g.start >= asked[-2] and g.end <= asked[-1] + EPS and self.src(g) == who
                                       and g.intact for g in self.by_bus[r.name])

    # -- arbitration --------------------------------------------------------------------------
    def arbitration(self, r: BusRules, frames: list[TraceFrame]) -> None:
        """After a corrupt frame a request starts only where the model's send guard allows it."""
        variant = self.rules.variants.get(r.name, "spec")
        slot, W = r.slot_s, r.window
        corrupt_ends = [f.end for f in self.corrupt[r.name]]
        # frames the model does not have (everything but requests) freeze the window's slot count
        other = [f for f in frames if not self.is_request(r, f)]
        other_end = [f.end for f in other]
        cum = [0.0]
        for f in other:
            cum.append(cum[-1] + (f.end - f.start))
        last_own: dict[str, float] = {}      # colliders scope: each slave's last corrupt echo
        for f in frames:
            if not self.is_request(r, f):
                continue
            who = self.src(f)
            code, i, rank = r.guards[who]
            k = bisect_left(corrupt_ends, f.start + EPS) - 1
            values = {f"ph{i}": arbitration.PENDING, "since": W, f"bo{i}": 0}
            if k >= 0 and variant == "spec":
                t0 = corrupt_ends[k]
                a, b = bisect_right(other_end, t0 + EPS), bisect_right(other_end, f.start + EPS)
                busy = sum(other[j].end - other[j].start for j in range(a, b) if other[j].start >= t0 - EPS)
                # the trace keeps whole microseconds: allow one per time read off it
                position = (f.start - t0 - busy + 1e-6 * (b - a + 2)) / slot
                values["since"] = min(W, int(position))
                if who in last_own:
                    values[f"bo{i}"] = max(0, arbitration.collision_backoff(r.arb, rank)
                                           - int((f.start - last_own[who]) / slot + 1e-6))
            self.report.checked["request_slot"] += 1
            if not eval(code, {}, {"v": values}):
                self.report.add(f, "backoff_slot", f"{who} (rank {rank}) sent {f.name} in slot "
                                f"{values['since']} of the window after the corrupt frame ending at "
                                f"{corrupt_ends[k]:.6f} s; its slot is {rank * r.arb.backoff_slots} "
                                f"(or from {W} on), spec arbitration.{self.rules.spec.buses[r.name].arbitration}")
            if f.line in self.collided:
                last_own[who] = f.end
        self.bound(r, frames)

    def bound(self, r: BusRules, frames: list[TraceFrame]) -> None:
        """Every request served within K slots, not counting the master's own transactions."""
        variant = self.rules.variants.get(r.name, "spec")
        k = r.bound.k_ticks if r.bound else None
        self.report.k_slots[r.name] = k
        service: set[int] = set()            # lines of frames that serve requests (the model's fetch/relay)
        episodes: dict[str, dict[str, Any]] = {}
        done: list[dict[str, Any]] = []
        noisy = [f.start for f in frames if f.lost or (not f.intact and f.line not in self.collided)]

        def close(slave: str, ep: dict[str, Any], t: float, how: str) -> None:
            ep["end"], ep["how"] = t, how
            done.append(ep)
            episodes.pop(slave, None)

        for idx, f in enumerate(frames):
            who, to = self.src(f), self.dst(f)
            if self.is_request(r, f):
                ep = episodes.get(who)
                if ep is not None and ep["through"] is not None:
                    close(who, ep, f.start, "declined")
                    ep = None
                if ep is None:
                    ep = episodes[who] = {"slave": who, "first": f, "through": None, "granted": None}
                if f.intact and f.line not in self.collided and ep["through"] is None:
                    ep["through"] = f
                continue
            if who == r.master and to in episodes and f.intact:
                fetch, _relay, _target = r.fetch[to]
                if f.name == fetch[0]:
                    episodes[to]["granted"] = f
                    service.add(f.line)
                continue
            if who in episodes and to == r.master and f.intact and episodes[who]["granted"] is not None:
                ep = episodes[who]
                service.add(f.line)
                _fetch, relay, target = r.fetch[who]
                end = f.end
                if relay:
                    nxt = next((g for g in frames[idx + 1:] if self.src(g) == r.master and g.name == relay[0]
                                and self.dst(g) == target), None)
                    if nxt is not None:
                        service.add(nxt.line)
                        end = nxt.end
                close(who, ep, end, "served")
        for who, ep in list(episodes.items()):
            close(who, ep, self.end_t, "open")
        # the master's own traffic: frames that neither request nor serve, and their gaps
        own = [f for f in frames if f.line not in service and not self.is_request(r, f)]
        own_start = [f.start for f in own]
        worst = 0.0
        posts = self._post_windows()
        for ep in done:
            self.report.requests += 1
            t1, t2 = ep["first"].start, ep["end"]
            # a request raised during a POST waits for it: counted from the INIT that ends it (seed 6.3)
            t1 = next((min(end, t2) for start, end in posts if start <= t1 < end), t1)
            if ep["how"] == "declined":
                self.report.declined += 1
                continue
            if any(t1 <= t <= t2 for t in noisy):
                self.report.unchecked += 1
                continue
            a, b = bisect_left(own_start, t1), bisect_left(own_start, t2)
            busy = sum(min(g.end, t2) - g.start + r.gap_s for g in own[a:b])
            wait = max(0.0, (t2 - t1 - busy)) / r.slot_s
            worst = max(worst, wait)
            if ep["how"] == "served":
                self.report.served += 1
            if k is None or wait <= k + 1e-6:
                continue
            if ep["how"] == "open" and ep["through"] is not None:
                self.report.declined += 1
                continue
            self.report.starved += 1
            if variant == "spec":
                what = "served" if ep["how"] == "served" else "still not served at the end of the trace"
                self.report.add(ep["first"], "bound_K", f"{ep['slave']}'s request {what} after {wait:.1f} slots "
                                f"of contention, more than K = {k} slots the checker proves for bus {r.name}")
        self.report.max_wait_slots[r.name] = max(self.report.max_wait_slots.get(r.name, 0.0), worst)

    def _post_windows(self) -> list[tuple[float, float]]:
        """The network's self tests: from the MCP's first ID_REQ of a POST to the end of the INIT broadcast
        that closes it (seed 6.3, 3.2.3), or the trace's end when none does. Masters identify their nodes
        then and serve no request; the K bound is the checker's arbitration model of the running network,
        so a request raised during a POST is counted from its INIT."""
        first_bus = self.rules.node[self.rules.mcp].masters
        windows: list[tuple[float, float]] = []
        start: float | None = None
        for f in self.by_bus.get(first_bus, []):
            if start is None and f.name == "ID_REQ" and self.src(f) == self.rules.mcp:
                start = f.start
            elif start is not None and f.name == "INIT" and self.dst(f) == "*":
                windows.append((start, f.end))
                start = None
        if start is not None:
            windows.append((start, self.end_t))
        return windows

    # -- identification ------------------------------------------------------------------------
    def id_exchanges(self, r: BusRules, frames: list[TraceFrame]) -> None:
        """seed 3.2.2: ID_REQ, timeout to the first byte, id_retries resends, then inactive."""
        attempts = r.id_retries + 1
        masters = self._master_frames(r, frames)
        for pos, j in enumerate(masters):
            f = frames[j]
            if f.name != "ID_REQ":
                continue
            node = self.dst(f)
            # seed 3.2.2: an ID_REQ heard corrupt (its echo too) is sent again, which is no retry (the id_retry
            # model's loss stands for it); a lost one is a try the node never heard, retried after the timeout
            n = sum(1 for p in self._id_run(r, frames, masters, pos, node) if not heard_corrupt(frames[masters[p]]))
            self.report.checked["id_req"] += 1
            if n > attempts:
                self.report.add(f, "id_retry", f"ID_REQ to {node}: attempt {n}, the spec allows "
                                f"{r.id_retries} resend(s) (buses.{r.name}.id_retries)")
            nxt = frames[masters[pos + 1]] if pos + 1 < len(masters) else None
            reply = self._reply(r, frames, j, node)
            if nxt is None:
                continue
            if not self.timed:
                if reply is None and n < attempts and not (nxt.name == "ID_REQ" and self.dst(nxt) == node):
                    self.report.add(nxt, "id_retry", f"no reply to ID_REQ {n} of {attempts} to {node}, but the "
                                    f"master sent {nxt.name} to {self.dst(nxt)} instead of resending (seed 3.2.2)")
                continue
            deadline = f.end + r.timeout_s
            if reply is not None and reply.start <= deadline + EPS:
                if nxt.start < reply.end - EPS:
                    self.report.add(nxt, "id_timeout", f"{nxt.name} to {self.dst(nxt)} while {node}'s ID_ACK, "
                                    f"begun within the timeout, was still on the line")
                continue
            if nxt.start < deadline - EPS:
                self.report.add(nxt, "id_timeout", f"{nxt.name} to {self.dst(nxt)} "
                                f"{(nxt.start - f.end) * 1e3:.2f} ms after ID_REQ to {node} ended with no reply: "
                                f"before the {r.timeout_s * 1e3:g} ms timeout (buses.{r.name}.response_timeout_ms)")
                continue
            again = nxt.name == "ID_REQ" and self.dst(nxt) == node
            if n < attempts and not again:
                self.report.add(nxt, "id_retry", f"no reply to ID_REQ {n} of {attempts} to {node}, but the master "
                                f"sent {nxt.name} to {self.dst(nxt)} instead of resending (one retry, seed 3.2.2)")
            elif again:
                busy_until = max((g.end for g in frames if g.start <= deadline + EPS and g.end > deadline), default=deadline)
                latest = max(deadline, busy_until, self._slaves_window_end(r, frames, f.end, nxt.start))
                if nxt.start > latest + r.gap_s + 2 * 10 * r.bit_s + EPS:
                    self.report.add(nxt, "id_timeout", f"ID_REQ to {node} resent {(nxt.start - f.end) * 1e3:.2f} ms "
                                    f"after the last, later than the {r.timeout_s * 1e3:g} ms timeout")

    def _slaves_window_end(self, r: BusRules, frames: list[TraceFrame], t1: float, t2: float) -> float:
        """When the master may talk again after the last corrupt frame ending in (t1, t2): the arbitration
        model gives the window after it to the slaves' requests (its master only listens), so a resend waits
        out the window and the master's defer slots (frames inside it add their time); t1 when there is none
        (a corrupt ID_REQ or ID_ACK, which the id_retry model counts as a loss, is such a frame)."""
        if r.arb is None:
            return t1
        ends = [c.end for c in self.corrupt.get(r.name, []) if t1 - EPS <= c.end <= t2 + EPS]
        if not ends:
            return t1
        inside = sum(g.end - g.start + r.gap_s for g in frames if ends[-1] - EPS <= g.start < t2 - EPS)
        return ends[-1] + (r.window + self.rules.defer_slots) * r.slot_s + inside

    def _master_frames(self, r: BusRules, frames: list[TraceFrame]) -> list[int]:
        return [j for j, f in enumerate(frames) if self.src(f) == r.master and f.parsed is not None]

    def _id_run(self, r: BusRules, frames: list[TraceFrame], masters: list[int], pos: int, node: str | None) -> list[int]:
        """The attempts of one identification ending at master frame `pos`: ID_REQs to `node` back to back
        (no other master frame between), none answered in time before the last."""
        run = [pos]
        while run[-1] > 0:
            p = run[-1] - 1
            g = frames[masters[p]]
            if g.name != "ID_REQ" or self.dst(g) != node or self._answered(r, frames, masters[p], node):
                break
            run.append(p)
        return run

    def _reply(self, r: BusRules, frames: list[TraceFrame], j: int, node: str | None) -> TraceFrame | None:
        """The first intact ID_ACK from `node` to the master after frame j, before the master's next frame."""
        for g in frames[j + 1:]:
            who = self.src(g)
            if who == r.master and g.parsed is not None:
                return None
            if who == node and g.intact and g.name == "ID_ACK" and g.parsed.message.address == g.parsed.src:
                return g
        return None

    def _answered(self, r: BusRules, frames: list[TraceFrame], j: int, node: str | None) -> bool:
        reply = self._reply(r, frames, j, node)
        return reply is not None and (not self.timed or reply.start <= frames[j].end + r.timeout_s + EPS)

    # -- POST ----------------------------------------------------------------------------------
    def post_verdicts(self) -> None:
        """seed 6.3: the MCP's verdict is the spec's rule over the nodes that answered on the wire."""
        verdicts = [n for n in self.trace.notes if n.event == "post_verdict"]
        for note in verdicts:
            answered = {s: self._node_answered(s, note.t) for s in self.rules.tree.by if s != self.rules.mcp}
            expect, named = post_model.expected_verdict(self.rules.post, self.rules.tree, answered)
            self.report.checked["post_verdict"] += 1
            missing = set() if note.fields.get("missing", "-") == "-" else set(note.fields["missing"].split(LIST_SEP))
            got = note.fields.get("verdict")
            absent = {s for s in answered if not self._present(answered, s)}
            if got != expect or missing != absent:
                self.report.add(None, "post_verdict", f"{note.node} says {got} missing {sorted(missing) or '-'}; "
                                f"the spec's rule over the nodes that answered says {expect} missing "
                                f"{sorted(absent) or '-'}", t=note.t, bus="debug", line=note.line)
        self.init_after_post(verdicts)

    def _present(self, answered: dict[str, bool], s: str) -> bool:
        n = self.rules.tree.by[s]
        return answered[s] and (n.master == self.rules.mcp or self._present(answered, n.master))

    def _node_answered(self, s: str, t: float) -> bool:
        """s answered its last ID exchange before t in time, reported no inactive status, and (a sub-master)
        sent its POST_REPORT when asked."""
        node = self.rules.node[s]
        r = self.rules.buses[node.bus]
        frames = [f for f in self.by_bus.get(node.bus, []) if f.start < t]
        masters = self._master_frames(r, frames)
        pos = next((p for p in range(len(masters) - 1, -1, -1) if frames[masters[p]].name == "ID_REQ"
                    and self.dst(frames[masters[p]]) == s), None)
        if pos is None:
            return False
        run = self._id_run(r, frames, masters, pos, s)
        if not any(self._answered(r, frames, masters[p], s) for p in run):
            return False
        last = masters[pos]
        for g in frames[last + 1:]:
            if self.src(g) == s and g.intact and g.name in self.rules.status_acks:
                status = getattr(g.parsed.message, "status", None)
                enum = next((fd.enum for fd in type(g.parsed.message).FIELDS if fd.name == "status"), None)
                if status is not None and enum is not None and enum(status).name in self.rules.inactive:
                    return False
        asked = [j for j, g in enumerate(frames) if j > last and g.name == "POST_QUERY" and self.dst(g) == s]
        if asked:
            got = any(g.name == "POST_REPORT" and self.src(g) == s and g.intact for g in frames[asked[0]:])
            if not got:
                return False
        return True

    def init_after_post(self, verdicts: list[TraceNote]) -> None:
        """seed 3.2.3: INIT via broadcasting once after each POST that did not halt."""
        first_bus = self.rules.node[self.rules.mcp].masters
        inits = [f for f in self.by_bus.get(first_bus, []) if f.name == "INIT" and self.dst(f) == "*"]
        for i, note in enumerate(verdicts):
            upto = verdicts[i + 1].t if i + 1 < len(verdicts) else float("inf")
            mine = [f for f in inits if note.t <= f.start < upto]
            self.report.checked["init_after_post"] += 1
            want = 0 if note.fields.get("verdict") == "HALTED" else 1
            if len(mine) > want:
                self.report.add(mine[want], "init_after_post", f"INIT broadcast {len(mine)} time(s) after a "
                                f"{note.fields.get('verdict')} POST (seed 3.2.3: once, after a POST that did not halt)")
            elif len(mine) < want and min(upto, self.end_t) - note.t > 1.0:
                self.report.add(None, "init_after_post", "no INIT broadcast after the POST passed (seed 3.2.3)",
                                t=note.t, bus=first_bus)
        for f in inits:
            if self.trace.notes and not any(n.t <= f.start for n in verdicts):   # a capture has no debug port
                self.report.add(f, "init_after_post", "INIT broadcast before any POST verdict")

    # -- relays through the MCP -------------------------------------------------------------------
    def first_bus_relays(self) -> None:
        """Every record reaching the MCP is relayed; MOVE_RELAYED resends follow protocol.move_retries."""
        bus = self.rules.node[self.rules.mcp].masters
        frames = self.by_bus.get(bus, [])
        mcp = self.rules.mcp
        for j, f in enumerate(frames):
            if f.name in self.rules.targeted and f.intact and self.dst(f) == mcp:
                m, relayed = f.parsed.message, self.rules.targeted[f.name]
                self.report.checked["record_relayed"] += 1
                want = (m.source, m.kind, m.channel, m.value)
                ok = any(g.name == relayed and self.src(g) == mcp and g.parsed.dst == m.target
                         and (g.parsed.message.address, g.parsed.message.kind, g.parsed.message.channel,
                              g.parsed.message.value) == want for g in frames[j + 1:])
                if not ok and self.end_t - f.end > 2.0:
                    self.report.add(f, "record_relayed", f"record of {self.rules.short.get(m.source)} from "
                                    f"{self.src(f)} to {self.rules.short.get(m.target)} never relayed by the MCP "
                                    f"(seed 3.2.2: every datum runs through the MCP)")
        for relayed, records in self.rules.command_relays.items():
            self.move_relays(frames, relayed, records)

    def move_relays(self, frames: list[TraceFrame], relayed: str, records: set[str]) -> None:
        """Resends of one relayed command (MOVE_RELAYED), a run ended by a new record (MOVE) carrying one."""
        mcp = self.rules.mcp
        relays = [j for j, f in enumerate(frames) if f.name == relayed and self.src(f) == mcp
                  and f.parsed.message.address != f.parsed.src]
        run: list[int] = []
        for j in relays + [None]:
            f = frames[j] if j is not None else None
            if run and f is not None and self._same_move(frames[run[-1]], f) and not any(
                    self._new_command(g, records, f.parsed.message.address) for g in frames[run[-1] + 1:j]):
                run.append(j)
            else:
                if run:
                    self._check_move_run(frames, run)
                run = [j] if j is not None else []

    def _new_command(self, g: TraceFrame, records: set[str], address: int) -> bool:
        """`g` starts a new command of `address`: a record carrying one (MOVE), or, for a reflex the MCP relays
        itself (seed 5.2, spec reflexes), a new record from the reflex's source, e.g. a second whisker touching."""
        if not g.intact:
            return False
        if g.name in records:
            return True
        return (g.name in self.rules.targeted and self.dst(g) == self.rules.mcp
                and g.parsed.message.source == address)

    @staticmethod
    def _same_move(a: TraceFrame, b: TraceFrame) -> bool:
        x, y = a.parsed.message, b.parsed.message
        return (x.address, x.mov_cmd, x.param) == (y.address, y.mov_cmd, y.param)

    def _check_move_run(self, frames: list[TraceFrame], run: list[int]) -> None:
        self.report.checked["move_relay"] += 1
        allowed = 1 + self.rules.move_retries
        if len(run) > allowed:
            f = frames[run[allowed]]
            self.report.add(f, "move_retries", f"{f.name} {f.parsed.message.describe()} sent {len(run)} times, "
                            f"protocol.move_retries allows {self.rules.move_retries} resend(s)")
        for a, b in zip(run, run[1:]):
            if not frames[a].intact:
                continue                  # seed 3.2.2: its echo came back corrupt (a collision), so it is sent again
            cmd = frames[a].parsed.message.mov_cmd
            acks = [g for g in frames[a + 1:b] if g.name == "STATUS_ACK_MMC" and g.intact]
            if not acks or self._applied(acks[-1].parsed.message, cmd):
                self.report.add(frames[b], "move_retries", "MOVE_RELAYED resent although no STATUS_ACK_MMC "
                                "showed the command not applied")

    @staticmethod
    def _applied(ack: M.StatusAckMmc, cmd: int) -> bool:
        return ack.gait == cmd if cmd in GAITS else ack.direction == cmd


    # -- the reflex rate behind the arbitration model's lead ---------------------------------------
    def reflex_rate(self) -> None:
        """spec reflexes.min_interval_ms, the rate that bounds the arbitration model's reflex lead: the source's
        `reflex_raised` notes at least that far apart."""
        for r in self.rules.buses.values():
            if r.arb is not None and arbitration.lead_slave(r.arb, self.rules.variants.get(r.name, "spec")) is not None:
                self._raise_rate(r, r.arb)

    def _raise_rate(self, r: BusRules, arb: spec_adapter.ArbParams) -> None:
        notes = [n for n in self.trace.notes if n.event == "reflex_raised" and n.node == arb.reflex]
        requests = [f for f in self.by_bus.get(r.name, []) if f.name == r.request and self.src(f) == arb.reflex]
        if requests and not notes:
            self.report.skipped["reflex_rate"] = (
                f"{arb.reflex} sent {len(requests)} {r.request} on bus {r.name} but the trace has no reflex_raised "
                f"note of it (no debug port in a capture, or a node that does not write it): its "
                f"{arb.reflex_gap_ms:g} ms rate limit (spec reflexes.min_interval_ms) is not checked")
            return
        self.report.checked["reflex_rate"] += len(notes)
        need = arb.reflex_gap_ms * 1e-3
        for a, b in zip(notes, notes[1:]):
            if b.t - a.t < need - 2e-6:        # two times read off the trace, each kept to the microsecond
                self.report.add(None, "reflex_rate", f"{arb.reflex} raised a reflex request "
                                f"{(b.t - a.t) * 1e3:.1f} ms after the last; spec reflexes.min_interval_ms is "
                                f"{arb.reflex_gap_ms:g} ms", t=b.t, bus="debug", line=b.line)


def validate(trace: Trace, spec: Any, variants: dict[str, str] | None = None, timed: bool = True) -> Report:
    """Check a trace against the spec's verified protocol; `variants` picks the arbitration rule per bus.

    `timed=False` for a capture whose time stamps are not the line's (a pty, a USB adapter's buffering):
    only the rules that need no clock run (ID retries by order, relays, MOVE retries, POST and INIT);
    one talker, backoff slots, the bound K and the ID timeout need a clock true to a character time."""
    return Validator(trace, Rules(spec, variants), timed).run()
