"""What every node's firmware shares beyond the generated skeleton: timers,
master transactions and slave-initiated frames (seed 3.2.2).

`Runtime` is a mixin placed before the generated skeleton in a behaviour's
bases (`class MMC(Runtime, MmcSkeleton)`): the skeleton frames, routes and
dispatches; this adds
  - `every(period, fn)`: a periodic timer on the board's clock;
  - `request(...)`: a master's transaction on the bus it masters, one at a
    time in order: the frame goes out after `master_defer_slots` request slots
    (so slaves' XMIT_REQ / DATA_RDY get the line), is resent after a corrupt
    echo, and a reply not begun within the bus's response timeout is retried
    `id_retries` times (seed 3.2.2: 10 ms, one retry);
  - `slave_send(...)`: a slave-initiated frame, started only on a line idle
    long enough that no polled reply can be due (Runtime._slave_start), resent after a corrupt echo following the
    bus's arbitration rule (address_backoff with scope `all`: after any corrupt
    frame every slave waits for its own slot, rank x backoff_slots, of the window
    that follows, counted in idle slots, one request per slot; the rule the model
    checker proves bounded and tracecheck holds every trace to). A request
    carrying a reflex (spec reflexes, seed 5.2) starts first, every other one
    reflex_lead_bits later, so the reflex is on the line first.
Bus timing comes from arachnae_proto.network.BUSES, protocol rules from the
host-supplied NetConfig: nothing here is a number of its own.
"""
from __future__ import annotations

from collections import deque
from typing import Any, Callable, NamedTuple

from arachnae_proto import CodecError
from arachnae_proto.frame import OVERHEAD, Frame, build, check
from arachnae_proto.messages import Message
from arachnae_proto.network import ADDRESS_OF, BROADCAST, BUSES, NODES

from behaviours.hardware import Hardware
from behaviours.netconfig import Config, NetConfig

Reply = Callable[[int, Message], None]
PREEMPT = 2        # Runtime.request: transactions of this priority or higher pass one still waiting out its defer
PRIORITY_GRANT = 2     # a master serves a request that got through before its own transactions (seed 3.2.2)
PRIORITY_RELAY = 3     # ... and relays the record it fetched before it grants the next request
PRIORITY_REFLEX = 4    # a reflex (spec reflexes, seed 5.2) before everything


class BusTiming:
    """One bus's timing from the spec (nodes.yaml `buses`, via arachnae_proto)."""

    __slots__ = ("bit_s", "char_s", "turnaround_s", "gap_s", "slot_s", "timeout_s", "id_retries")

    def __init__(self, bus: str) -> None:
        b = BUSES[bus]
        self.bit_s = 1 / b.baud
        self.char_s = b.bits_per_char / b.baud
        self.turnaround_s = b.turnaround_us * 1e-6
        # spec buses: the least idle time before any frame, the turnaround and the gap that delimits frames
        self.gap_s = max(self.turnaround_s, b.idle_gap_chars * self.char_s)
        # spec arbitration.slot = request_frame: one request frame (no payload) plus the frame gap
        self.slot_s = OVERHEAD * self.char_s + self.gap_s
        self.timeout_s = b.response_timeout_ms / 1000
        self.id_retries = b.id_retries


class SlaveQuiet(NamedTuple):
    """Idle line time (s) a slave waits before it starts a frame of its own (Runtime._slave_start), by what the
    line carried last; the rank stagger and the reflex lead included. firmware/roles.py writes these for the C."""
    after_master: float
    after_other: float
    in_window: float


def slave_quiet(t: BusTiming, net: NetConfig, rank: int, reflex_request: bool) -> SlaveQuiet:
    """The idle times of Runtime._slave_start (see there for why) for a slave of arbitration rank `rank`."""
    # seed 5.2 / spec arbitration reflex_lead_bits: an ordinary request waits longer than a reflex one
    lead = 0.0 if not net.reflexes or reflex_request else net.reflex_lead_bits * t.bit_s
    extra = rank * 2 * t.bit_s + lead
    # two characters short of the master's defer: the line is polled a character at a time
    after_master = min(t.timeout_s, net.protocol.master_defer_slots * t.slot_s - 2 * t.char_s)
    return SlaveQuiet(after_master + extra, t.gap_s + t.char_s + extra, t.turnaround_s + extra)


def arbitration_rank(net: NetConfig, bus: str, address: int) -> int:
    """A slave's arbitration rank on `bus` (spec rank_order: declared priority, then address)."""
    slaves = net.requesters.get(bus, ())
    return slaves.index(address) if address in slaves else len(slaves)


def slaves_of(bus: str) -> list[int]:
    """Addresses of the nodes sitting on `bus` as slaves, ascending."""
    return sorted(a for a, node in NODES.items() if node.bus == bus)


class Request:
    __slots__ = ("dst", "msg", "expect", "on_reply", "on_timeout", "retries", "timeout", "serial", "sent", "priority")

    def __init__(self, dst: int, msg: Message, expect: tuple, on_reply: Reply | None,
                 on_timeout: Callable[[], None] | None, retries: int, timeout: float) -> None:
        self.dst, self.msg, self.expect, self.on_reply = dst, msg, expect, on_reply
        self.on_timeout, self.retries, self.timeout, self.serial = on_timeout, retries, timeout, 0
        self.sent = False
        self.priority = 0


class MasterLink:
    """A master's side of the bus it polls: one transaction at a time, in order."""

    __slots__ = ("bus", "timing", "queue", "current", "serial", "frame")

    def __init__(self, bus: str) -> None:
        self.bus, self.timing = bus, BusTiming(bus)
        self.queue: deque[Request] = deque()
        self.current: Request | None = None
        self.serial = 0
        self.frame = b""


class Runtime:
    """Mixin for a generated skeleton: constructor (address, transmit, hw, cfg)."""

    def __init__(self, address: int, transmit: Callable[[str, bytes], None], hw: Hardware, cfg: Config) -> None:
        super().__init__(address, transmit)  # type: ignore[call-arg]
        self.hw, self.cfg, self.net = hw, cfg, cfg.net
        self.master_bus: str | None = NODES[address].masters
        self.links: dict[str, MasterLink] = {self.master_bus: MasterLink(self.master_bus)} if self.master_bus else {}
        self._slave_out: dict[str, deque[bytes]] = {}
        self._timings: dict[str, BusTiming] = {}
        self._collision_at: dict[str, float] = {}   # bus -> when the last corrupt frame ended
        self._window_pause: dict[str, float] = {}   # bus -> line time since then taken by frames other than requests
        self._quiet_until: dict[str, float] = {}    # mastered bus -> the slaves' window after a corrupt frame ends
        self._slot_used: set[str] = set()           # buses where this slave sent in its slot of the open window
        self._after_master: dict[str, bool] = {}    # bus -> the last frame heard on it came from its master

    def note(self, event: str, **data: Any) -> None:
        """The skeleton's trace notes (a dropped message) go to the board's debug port, like the behaviour's own."""
        self.hw.note(event, **data)

    # --- life cycle and time ------------------------------------------------------------
    def start(self) -> None:
        """Power-on (t = 0). Behaviours start their timers and their POST here."""

    @property
    def now(self) -> float:
        return self.hw.now()

    def every(self, period: float, fn: Callable[[], Any]) -> None:
        """Call fn now and every `period` seconds."""
        after = self.hw.after

        def run() -> None:
            fn()
            after(period, run)
        after(0.0, run)

    # --- master side ----------------------------------------------------------------------
    def request(self, dst: int, msg: Message, expect: tuple = (), on_reply: Reply | None = None,
                on_timeout: Callable[[], None] | None = None, retries: int | None = None,
                timeout: float | None = None, urgent: bool = False, priority: int = 0) -> None:
        """Queue a transaction on the bus this node masters. `expect`: reply classes; empty: done once sent.
        `urgent`: ahead of every ordinary one, after the urgent ones queued earlier. `priority` >= PREEMPT: after those of the
        same or a higher priority, ahead of the rest, even of a lower one still waiting out its defer (not yet on
        the wire), which goes back to the queue (spec reflexes, seed 5.2: a reflex does not wait for it)."""
        link = self.links[self.master_bus]  # type: ignore[index]
        t = link.timing
        req = Request(dst, msg, expect, on_reply, on_timeout, t.id_retries if retries is None else retries,
                      t.timeout_s if timeout is None else timeout)
        req.priority = max(priority, 1 if urgent else 0)
        cur = link.current
        if req.priority >= PREEMPT and cur is not None and not cur.sent and cur.priority < req.priority:
            req.serial = cur.serial            # the defer already under way now sends this one
            cur.serial = 0
            self._enqueue(link, cur, front=True)
            link.current = req
            return
        # urgent ones in the order queued, after those queued earlier (the arbitration model's master serves
        # requests in the order they got through; LIFO starved a sensor, found by tracecheck's K bound)
        self._enqueue(link, req, front=False)
        if link.current is None:
            self._next(link)

    @staticmethod
    def _enqueue(link: MasterLink, req: Request, front: bool) -> None:
        """Into the queue by priority: at the front of its priority (`front`) or at its end."""
        q = link.queue
        i = next((k for k, r in enumerate(q) if (r.priority <= req.priority if front else r.priority < req.priority)),
                 len(q))
        q.insert(i, req)

    def waiting(self, dst: int, msg: type[Message], priority: int = 0) -> bool:
        """A transaction sending a `msg` to `dst`, of `priority` or higher (Runtime.request), is queued on the
        mastered bus and not yet on the wire."""
        link = self.links[self.master_bus]  # type: ignore[index]
        cur = link.current
        return any(r.dst == dst and type(r.msg) is msg and r.priority >= priority
                   for r in ([cur] if cur is not None and not cur.sent else []) + list(link.queue))

    def _next(self, link: MasterLink) -> None:
        if link.current is not None:
            return
        if not link.queue:
            return
        link.serial += 1
        req = link.queue.popleft()
        req.serial = link.serial
        link.current = req
        # spec protocol.master_defer_slots: leave the line to slaves' requests for this many slots
        self.hw.after(self.net.protocol.master_defer_slots * link.timing.slot_s, self._transmit, link, req.serial)

    def _transmit(self, link: MasterLink, serial: int) -> None:
        req = link.current
        if req is None or req.serial != serial:
            return
        quiet = self._quiet_until.get(link.bus, 0.0) - self.now
        if quiet > 0:
            # spec arbitration (scope all): after a corrupt frame the slaves own the window's slots; the
            # arbitration model's master only listens then, and a master frame in a slot costs a slave its turn
            self.hw.after(quiet, self._transmit, link, serial)
            return
        req.sent = True
        if req.dst == BROADCAST:                  # seed 3.2.1: 0xFF, every node of the bus
            link.frame = self.broadcast(link.bus, req.msg)  # type: ignore[attr-defined]
        else:
            link.frame = self.send(req.dst, req.msg)  # type: ignore[attr-defined]

    def _timeout(self, link: MasterLink, serial: int) -> None:
        req = link.current
        if req is None or req.serial != serial:
            return
        # spec protocol.response_timeout_to = first_byte: a reply already on the line is waited for
        if self.net.protocol.response_timeout_to == "first_byte" and self.hw.line_idle_s(link.bus) == 0.0:
            self.hw.after(link.timing.char_s, self._timeout, link, serial)
            return
        if req.retries > 0:
            req.retries -= 1
            self._transmit(link, serial)
            return
        link.current = None
        if req.on_timeout is not None:
            req.on_timeout()
        self._next(link)

    def dispatch(self, frame: Frame) -> None:
        """A reply the current transaction waits for completes it; everything else goes to the on_ hooks."""
        bus = self.routes.get(frame.src)  # type: ignore[attr-defined]
        link = self.links.get(bus) if bus is not None else None
        if link is not None:
            req = link.current
            if req is not None and frame.src == req.dst and type(frame.message) in req.expect:
                link.current = None
                if req.on_reply is not None:
                    req.on_reply(frame.src, frame.message)
                self._next(link)
                return
        super().dispatch(frame)  # type: ignore[misc]

    # --- echo: the transceiver reads back every frame this node sends (seed 3.2.2) --------------
    def on_echo(self, bus: str, sent: bytes, heard: bytes) -> None:
        self.on_line_frame(bus, heard)
        link = self.links.get(bus)
        if link is not None and link.current is not None and sent == link.frame:
            req, serial = link.current, link.current.serial
            if heard != sent:                      # seed 3.2.2: corrupt echo -> send again
                # off the wire again while it waits out the slaves' window: a reflex fetch queued meanwhile goes
                # first (spec reflexes, seed 5.2; worst_contention seed 1: a PSC poll that collided kept the
                # whisker's fetch waiting through two resend waits, the LSC past K)
                req.sent = False
                self.hw.after(self._master_resend_wait(link), self._transmit, link, serial)
            elif not req.expect:
                link.current = None
                self._next(link)
            else:
                self.hw.after(req.timeout, self._timeout, link, serial)
            return
        self._slave_echo(bus, sent, heard)

    def _master_resend_wait(self, link: MasterLink) -> float:
        """After a corrupt frame the master resends only once the slaves' backoff window has passed,
        plus its usual defer slots: resending at once would meet the slave whose slot comes first, and
        both would retry in lockstep forever (found in the simulator; the window is the spec's rule)."""
        t = link.timing
        if self.net.arbitration.get(link.bus) != "address_backoff":
            return t.turnaround_s
        window = len(self.net.requesters.get(link.bus, ())) * self.net.backoff_slots * t.slot_s
        return window + self.net.protocol.master_defer_slots * t.slot_s

    # --- slave side -------------------------------------------------------------------------
    def slave_send(self, dst: int, msg: Message) -> None:
        """A frame the slave starts on its own (XMIT_REQ, DATA_RDY): resent until its echo is clean."""
        bus = self.routes[dst]  # type: ignore[attr-defined]
        if self.net.arbitration.get(bus) == "polled":
            raise ValueError(f"bus {bus} is polled: slaves never start a frame (spec arbitration)")
        if type(msg) not in self.SENDS:  # type: ignore[attr-defined]
            raise ValueError(f"{self.ROLE} does not send {msg.NAME} (spec)")  # type: ignore[attr-defined]
        q = self._slave_out.setdefault(bus, deque())
        q.append(build(dst, self.address, msg))  # type: ignore[attr-defined]
        if len(q) == 1:
            self._slave_start(bus)

    def _slave_start(self, bus: str) -> None:
        """seed 3.2.2: a slave starts its own frame only "when the bus is idle". After a master's frame a
        polled slave's reply starts up to the response timeout later (on the sensor bus the frame gap alone
        is 6.3 ms), so a request started earlier would hit that reply (found by the trace validator: an
        XMIT_REQ meeting the SPU's XMIT_RECORD). Idle therefore means: after a frame of the master, for the
        response timeout, cut to the master_defer_slots the master leaves free (a reply later than that meets
        the master's next frame anyway); after any other frame, for the frame gap and a character (a master
        frame already waiting for the line goes first); inside the backoff window after a corrupt frame, for
        the turnaround (the master keeps off the line); plus two bit times per rank among the bus's
        requesting slaves, so two slaves waiting for the same idle line start apart and the later one hears
        the first one's carrier; plus the reflex lead for an ordinary request (slave_quiet)."""
        q = self._slave_out.get(bus)
        if not q:
            return
        t = self._timing(bus)
        need = slave_quiet(t, self.net, self.rank(bus), self.reflex_request(bus))
        if self._in_window(bus):
            quiet = need.in_window
        elif self._after_master.get(bus, True):
            quiet = need.after_master
        else:
            quiet = need.after_other
        idle = self.hw.line_idle_s(bus)
        if idle <= quiet:                        # first the line, so a frame on it cannot cost our slot
            self.hw.after(quiet - idle + t.char_s if idle > 0 else t.char_s, self._slave_start, bus)
            return
        wait = self._backoff_wait(bus)
        if wait > 0:
            self.hw.after(wait, self._slave_start, bus)
            return
        if self._in_window(bus):
            self._slot_used.add(bus)             # one request per slot: the next waits for the window's end
        self.transmit(bus, q[0])  # type: ignore[attr-defined]

    def reflex_request(self, bus: str) -> bool:
        """Does the request this slave is about to start on `bus` carry a reflex record (spec reflexes)?
        The reflex's source always does; a relaying sub-master overrides this for the records it holds."""
        return self.net.reflex_from(self.address) is not None  # type: ignore[attr-defined]

    def _slave_echo(self, bus: str, sent: bytes, heard: bytes) -> None:
        q = self._slave_out.get(bus)
        if not q or sent != q[0]:
            return
        if heard == sent:
            q.popleft()
            if q:
                self._slave_start(bus)
        elif self._scope_all(bus):
            self._open_window(bus)               # seed 3.2.2: corrupt echo; spec: wait for our slot
            self._slave_start(bus)
        else:
            self.hw.after(self._backoff(bus), self._slave_start, bus)

    def on_codec_error(self, bus: str, err: Any) -> None:
        """A corrupt frame on one of our buses: with scope `all`, every slave enters the backoff window."""
        if self._scope_all(bus) and bus != self.master_bus:
            self._open_window(bus)

    def _open_window(self, bus: str) -> None:
        self._collision_at[bus] = self.now
        self._window_pause[bus] = 0.0
        self._slot_used.discard(bus)

    def on_line_frame(self, bus: str, data: bytes) -> None:
        """Every frame the UART hears on a bus, ended just now (the receiver's byte stream, own frames by
        their echo). The window's slots are idle slots (spec arbitration rule): a frame other than a
        request, e.g. the master serving one, does not use up a slot, so the window stands still."""
        try:
            _dst, src, opcode, _payload = check(data)
        except CodecError:
            src = opcode = None
        if bus != self.master_bus:                   # a reply may follow the master's frame
            self._after_master[bus] = src is None or src == ADDRESS_OF[BUSES[bus].master]
        if not self._scope_all(bus):
            return
        if opcode is None:
            if bus == self.master_bus:               # the slaves contend now: the master keeps off the line
                self._quiet_until[bus] = self.now + self._master_resend_wait(self.links[bus])
            else:
                self._open_window(bus)               # any corrupt frame, our own echo included
            return
        if bus == self.master_bus:
            return
        if bus in self._collision_at and opcode != self.net.request_opcodes.get(bus):
            self._window_pause[bus] += len(data) * self._timing(bus).char_s

    def _scope_all(self, bus: str) -> bool:
        return self.net.arbitration.get(bus) == "address_backoff" and self.net.backoff_scope == "all"

    def _backoff_wait(self, bus: str) -> float:
        """Seconds until this slave may start a request: its slot in the window after a collision
        (rank x backoff_slots slots, less its last bit), or the window's end if the slot has passed; 0 when free."""
        at = self._collision_at.get(bus)
        if at is None or not self._scope_all(bus):
            return 0.0
        at += self._window_pause.get(bus, 0.0)     # idle slots: the window stood still while others talked
        t = self._timing(bus)
        slaves = self.net.requesters.get(bus, ())   # spec: rank among the bus's requesting slaves
        step = self.net.backoff_slots * t.slot_s
        mine, end = at + self.rank(bus) * step, at + len(slaves) * step
        now = self.now
        if now >= end:
            return 0.0
        if bus in self._slot_used:
            return end - now
        if now < mine:
            return mine - now
        # seed 3.2.2 / spec address_backoff: start inside our own slot, at least a bit before it ends. A start at
        # its very end (float noise: frame_loss seed 7, the SPU 1e-14 s short of it) is the next rank's slot start
        # to the line and to the trace validator, and meets that rank's request (firmware: sensor.c backing_off)
        if now < mine + step - t.bit_s:
            return 0.0
        return end - now

    def _in_window(self, bus: str) -> bool:
        """The backoff window after a corrupt frame is still open (scope all), in idle slots."""
        at = self._collision_at.get(bus)
        if at is None or not self._scope_all(bus):
            return False
        t = self._timing(bus)
        window = len(self.net.requesters.get(bus, ())) * self.net.backoff_slots * t.slot_s
        return self.now < at + self._window_pause.get(bus, 0.0) + window

    def _timing(self, bus: str) -> BusTiming:
        t = self._timings.get(bus)
        if t is None:
            t = self._timings[bus] = BusTiming(bus)
        return t

    def _backoff(self, bus: str) -> float:
        """seed 3.2.2 resends at once; spec address_backoff waits (rank + 1) slots, rank by ascending address."""
        t = self._timing(bus)
        if self.net.arbitration.get(bus) != "address_backoff":
            return t.turnaround_s
        return (self.rank(bus) + 1) * self.net.backoff_slots * t.slot_s

    def rank(self, bus: str) -> int:
        """This slave's arbitration rank on `bus` (spec rank_order: declared priority, then address)."""
        return arbitration_rank(self.net, bus, self.address)  # type: ignore[attr-defined]
