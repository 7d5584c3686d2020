"""What every simulated node shares: bytes in and out through the codec, timers,
the generic INIT / ID_REQ / STATUS_REQ answers, and request/response with the
bus's response timeout and retry for masters.

Stand-in for the generated node skeleton (generated/python): the typed
dispatch `on_<message>` and the generic handlers have the same shape, so each
role's module will subclass the generated skeleton instead of this class.
"""
from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Callable

from sim2d.bus import Port

if TYPE_CHECKING:
    from sim2d.sim import Context


@dataclass
class Request:
    dst: int
    name: str
    raw: dict[str, Any]
    expect: tuple[str, ...] = ()          # reply messages; empty: done when the frame is out
    on_reply: Callable[[int, str, dict], None] | None = None
    on_timeout: Callable[[], None] | None = None
    retries: int = 1
    timeout: float | None = None          # None: the bus's response timeout from the spec
    sent_at: float = 0.0
    serial: int = 0


@dataclass
class MasterLink:
    """A master's side of the bus it polls: one transaction at a time, in order."""

    bus: str
    queue: deque = field(default_factory=deque)
    current: Request | None = None
    serial: int = 0


class NodeProcess:
    """A node as the simulator drives it: on_bytes, tick, and send()."""

    tick_period: float | None = None

    def __init__(self, node: Any, ctx: "Context"):
        self.node = node
        self.ctx = ctx
        self.address = node.address
        self.short = node.short
        self.ports: dict[str, Port] = {}
        self.alive = True
        self.links: dict[str, MasterLink] = {}
        self.pending_slave: dict[str, deque] = {}
        self.status = 0      # IN_ORDER / NOT_BUSY

    # --- wiring -----------------------------------------------------------
    def attach(self, bus: str, port: Port) -> None:
        self.ports[bus] = port
        if bus == self.node.masters:
            self.links[bus] = MasterLink(bus)

    def start(self) -> None:
        """Called once at power-on (t = 0)."""

    # --- time ---------------------------------------------------------------
    @property
    def now(self) -> float:
        return self.ctx.sched.now

    def after(self, delay: float, fn: Callable[..., Any], *args: Any) -> None:
        def run() -> None:
            if self.alive:
                fn(*args)
        self.ctx.sched.after(delay, run)

    def tick(self, t: float) -> None:
        """Periodic work every `tick_period` seconds (None: no ticks)."""

    # --- bytes --------------------------------------------------------------
    def send(self, bus: str, dst: int, name: str, **raw: Any) -> None:
        if self.alive:
            self.ports[bus].send(self.ctx.codec.encode(name, dst, self.address, **raw))

    def on_bytes(self, bus: str, t: float, data: bytes) -> None:
        if not self.alive:
            return
        msg = self.ctx.decode(data)
        if msg is None:
            return
        if msg.dst != self.address and msg.dst != self.ctx.spec.broadcast:
            return
        link = self.links.get(bus)
        if link is not None and link.current is not None and msg.src == link.current.dst and msg.name in link.current.expect:
            req = link.current
            link.current = None
            if req.on_reply:
                req.on_reply(msg.src, msg.name, msg.fields)
            self._next(link)
            return
        handler = getattr(self, "on_" + msg.name.lower(), None)
        if handler is not None:
            handler(bus, msg.src, msg.fields)

    def on_echo(self, bus: str, t: float, sent: bytes, heard: bytes) -> None:
        if not self.alive:
            return
        link = self.links.get(bus)
        if link is not None and link.current is not None and sent == link.current_frame:  # type: ignore[attr-defined]
            req = link.current
            if heard != sent:                      # seed 3.2.2: a corrupt echo -> send again
                self.after(self.ctx.buses[bus].turnaround, self._transmit, link)
                return
            if not req.expect:
                link.current = None
                self._next(link)
                return
            timeout = req.timeout if req.timeout is not None else self.ctx.spec.buses[bus].response_timeout_ms / 1000
            self.after(timeout, self._timeout, link, req.serial)
            return
        q = self.pending_slave.get(bus)
        if q and sent == q[0]:
            if heard != sent:
                # seed 3.2.2 + spec arbitration address_backoff: wait (rank + 1) slots, then resend
                self.after(self.ctx.backoff(bus, self.address), self._slave_resend, bus)
            else:
                q.popleft()

    def _slave_resend(self, bus: str) -> None:
        q = self.pending_slave.get(bus)
        if q:
            self.ports[bus].send(q[0])

    def slave_send(self, bus: str, dst: int, name: str, **raw: Any) -> None:
        """A slave-initiated frame (XMIT_REQ, DATA_RDY): resent after a corrupt echo."""
        if not self.alive:
            return
        frame = self.ctx.codec.encode(name, dst, self.address, **raw)
        self.pending_slave.setdefault(bus, deque()).append(frame)
        self.ports[bus].send(frame)

    # --- master side ----------------------------------------------------------
    def request(self, bus: str, req: Request) -> None:
        link = self.links[bus]
        link.queue.append(req)
        if link.current is None:
            self._next(link)

    def _next(self, link: MasterLink) -> None:
        if link.current is not None or not link.queue or not self.alive:
            return
        link.serial += 1
        req = link.queue.popleft()
        req.serial = link.serial
        link.current = req
        # leave one request slot free so a slave's XMIT_REQ / DATA_RDY can get the line (see report)
        self.after(self.ctx.master_gap(link.bus), self._transmit, link)

    def _transmit(self, link: MasterLink) -> None:
        req = link.current
        if req is None:
            return
        frame = self.ctx.codec.encode(req.name, req.dst, self.address, **req.raw)
        link.current_frame = frame  # type: ignore[attr-defined]
        req.sent_at = self.now
        self.ports[link.bus].send(frame)

    def _timeout(self, link: MasterLink, serial: int) -> None:
        req = link.current
        if req is None or req.serial != serial:
            return
        port = self.ports[link.bus]
        if not port.line_idle():                   # a reply has started: wait for its end
            self.after(port.bus.char_time, self._timeout, link, serial)
            return
        if req.retries > 0:
            req.retries -= 1
            self._transmit(link)
            return
        link.current = None
        if req.on_timeout:
            req.on_timeout()
        self._next(link)

    # --- generic handlers (seed 3.2.x: every node answers these) ---------------------
    def reply(self, bus: str, dst: int, name: str, **raw: Any) -> None:
        self.send(bus, dst, name, **raw)

    def on_id_req(self, bus: str, src: int, f: dict) -> None:
        self.reply(bus, src, "ID_ACK", address=self.address)

    def on_init(self, bus: str, src: int, f: dict) -> None:
        self.reset()

    def reset(self) -> None:
        """INIT: back to the power-on state (nothing to forget by default)."""

    def status_message(self) -> str:
        for name in ("STATUS_ACK_ORDER", "STATUS_ACK_RANGE", "STATUS_ACK_BUSY"):
            if self.node.role in self.ctx.spec.message(name).senders:
                return name
        return ""

    def on_status_req(self, bus: str, src: int, f: dict) -> None:
        name = self.status_message()
        if name:
            self.reply(bus, src, name, status=self.status)

    # --- faults -------------------------------------------------------------
    def kill(self) -> None:
        self.alive = False


POST_REPORT_TIMEOUT = 2.0   # CHOICE: how long a master waits for a sub-master's POST_REPORT


class Master(NodeProcess):
    """A bus master: runs the hierarchical POST on its own bus (seed 6.3, SPEC-NOTES decision 2)."""

    def __init__(self, node: Any, ctx: "Context"):
        super().__init__(node, ctx)
        self.post_missing: list[int] | None = None     # None while POST runs
        self.post_waiting: list[tuple[str, int]] = []  # POST_QUERYs to answer when done

    def run_post(self, done: Callable[[list[int]], None] | None = None) -> None:
        bus = self.node.masters
        spec = self.ctx.spec
        slaves = sorted(spec.slaves(bus), key=lambda n: n.address)
        missing: list[int] = []
        inactive = {spec.enums[e].values[s] for e in ("ORDER_STATUS", "RANGE_STATUS") for s in spec.post.inactive_statuses
                    if s in spec.enums[e].values}
        retries = spec.buses[bus].id_retries

        def below(n: Any) -> list[int]:
            """Every node behind a missing sub-master is missing too."""
            out = []
            if n.masters:
                for m in spec.slaves(n.masters):
                    out += [m.address] + below(m)
            return out

        def lost(n: Any) -> None:
            missing.append(n.address)
            missing.extend(below(n))

        for n in slaves:
            def on_status(src: int, name: str, f: dict, n: Any = n) -> None:
                if name != "STATUS_ACK_BUSY" and f.get("status") in inactive:
                    lost(n)

            def on_ack(src: int, name: str, f: dict, n: Any = n) -> None:
                if n.role in spec.message("STATUS_ACK_BUSY").senders:
                    return
                self.request(bus, Request(n.address, "STATUS_REQ", {}, ("STATUS_ACK_ORDER", "STATUS_ACK_RANGE", "STATUS_ACK_MMC"),
                                          on_status, lambda n=n: lost(n), retries))
            self.request(bus, Request(n.address, "ID_REQ", {}, ("ID_ACK",), on_ack, lambda n=n: lost(n), retries))

        def finish() -> None:
            self.post_missing = sorted(set(missing))
            self.ctx.record_post(self.short, self.post_missing)
            for b, src in self.post_waiting:
                self._post_report(b, src)
            self.post_waiting.clear()
            if done:
                done(self.post_missing)

        def query_subs() -> None:
            for n in slaves:
                if n.masters and n.address not in missing:
                    def on_report(src: int, name: str, f: dict) -> None:
                        missing.extend(f["missing"])
                    self.request(bus, Request(n.address, "POST_QUERY", {}, ("POST_REPORT",), on_report,
                                              lambda n=n: lost(n), retries, POST_REPORT_TIMEOUT))
            self._after_queue(bus, finish)

        self._after_queue(bus, query_subs)

    def _after_queue(self, bus: str, fn: Callable[[], Any]) -> None:
        """Run fn once every request queued so far on `bus` has finished."""
        link = self.links[bus]
        if link.current is None and not link.queue:
            fn()
            return
        self.after(self.ctx.buses[bus].char_time * 4, self._after_queue, bus, fn)

    def on_post_query(self, bus: str, src: int, f: dict) -> None:
        if self.post_missing is None:
            self.post_waiting.append((bus, src))
        else:
            self._post_report(bus, src)

    def _post_report(self, bus: str, src: int) -> None:
        miss = self.post_missing or []
        self.reply(bus, src, "POST_REPORT", missing_count=len(miss), missing=bytes(miss))
