"""A half-duplex RS-485 bus as discrete events, carrying bytes (seed 3.2.1/3.2.2).

A frame occupies the line for len * bits_per_char / baud seconds. A sender
waits for the line to be idle plus the turnaround time (carrier sense); two
senders that start within one bit time of each other collide, and every
station, senders included, then hears the wired-AND of both frames. Each
sender hears its own frame back (the echo the seed uses to detect
corruption). Loss, corruption and delay can be injected per bus; a station
can be muted (its transmitter is dead) or killed (it neither hears nor talks).
Stations can be made deaf to each other's requests for one character time:
their requests started that close together then collide instead of deferring
by carrier sense (the slaves' rank stagger is a few bit times), which is the
arbitration model's collision of requests sent in the same slot (a checker's
counterexample replays with it, model_check.replay).
"""
from __future__ import annotations

import random
from dataclasses import dataclass, field
from typing import Callable

from sim2d.events import Scheduler

Receiver = Callable[[str, float, bytes], None]
Echo = Callable[[str, float, bytes, bytes], None]     # bus, t, sent, heard


@dataclass
class Fault:
    loss: float = 0.0       # probability a frame is lost for every receiver but the sender
    corrupt: float = 0.0    # probability one bit of the frame flips on the line
    delay: float = 0.0      # seconds added before receivers (not the echo) get the frame


@dataclass
class Transmission:
    port: "Port"
    data: bytes
    start: float
    end: float
    collided: bool = False
    partners: list = field(default_factory=list)   # transmissions it overlapped with


@dataclass
class TraceEntry:
    start: float
    end: float
    bus: str
    sender: str
    sent: bytes
    heard: bytes | None          # what receivers got (None: lost)
    flags: tuple[str, ...] = ()


@dataclass
class BusStats:
    frames: int = 0
    busy_s: float = 0.0
    collisions: int = 0
    lost: int = 0
    corrupted: int = 0
    delayed: int = 0
    bytes: int = 0


class Port:
    """A station's connection to one bus."""

    def __init__(self, bus: "Bus", owner: str, receiver: Receiver, echo: Echo | None = None):
        self.bus, self.owner, self.receiver, self.echo = bus, owner, receiver, echo
        self.queue: list[bytes] = []
        self.muted = False
        self.killed = False
        self._pending = False
        self.driven_at: float | None = None   # when the station drove the line, if before it reached the bus

    def send(self, data: bytes, driven_at: float | None = None) -> None:
        """Queue a frame; it goes out when the line is free (in order, one at a time). `driven_at`: a
        co-simulated station (firmware/sil_bridge.py) reports its frames up to a sync period late; its carrier
        sense is judged at the time it drove the line."""
        if self.killed:
            return
        self.driven_at = driven_at
        self.queue.append(bytes(data))
        if not self._pending:
            self._pending = True
            self.bus._schedule_start(self)

    @property
    def sending(self) -> bool:
        return self._pending


class Bus:
    def __init__(self, name: str, sched: Scheduler, baud: int, bits_per_char: int, turnaround_s: float,
                 rng: random.Random, trace: Callable[[TraceEntry], None] | None = None):
        self.name, self.sched = name, sched
        self.baud, self.bits_per_char, self.turnaround = baud, bits_per_char, turnaround_s
        self.bit_time = 1.0 / baud
        self.char_time = bits_per_char / baud
        self.rng = rng
        self.trace = trace
        self.ports: list[Port] = []
        self.active: list[Transmission] = []
        self.idle_at = 0.0
        self.busy_since = 0.0
        self.fault = Fault()
        self.stats = BusStats()
        self.deaf: frozenset[str] = frozenset()     # stations that miss each other's request carrier
        self.deaf_opcode: int | None = None         # ... for frames with this opcode (the bus's request)

    def attach(self, owner: str, receiver: Receiver, echo: Echo | None = None) -> Port:
        port = Port(self, owner, receiver, echo)
        self.ports.append(port)
        return port

    def frame_time(self, nbytes: int) -> float:
        return nbytes * self.char_time

    def idle(self) -> bool:
        return not self.active and self.sched.now >= self.idle_at

    def idle_for(self, owner: str | None = None) -> float:
        """Seconds since the line went idle; 0.0 while a frame is on it (that `owner` can hear)."""
        if self.active and self._unheard(owner, self.deaf_opcode):
            return self.sched.now - self.idle_at
        return self.sched.now - self.idle_at if not self.active and self.sched.now >= self.idle_at else 0.0

    def _unheard(self, owner: str | None, opcode: int | None) -> bool:
        """`owner`, about to send a request, cannot hear what is on the line: requests of stations it is
        deaf to, begun less than a character time ago."""
        if owner not in self.deaf or opcode is None or opcode != self.deaf_opcode:
            return False
        now = self.sched.now
        return all(tx.port.owner in self.deaf and tx.port.owner != owner and len(tx.data) > 2
                   and tx.data[2] == opcode and now - tx.start < self.char_time for tx in self.active)

    def _schedule_start(self, port: Port) -> None:
        t = max(self.sched.now, self.idle_at + self.turnaround if self.idle_at > 0 else self.sched.now)
        self.sched.at(t, self._try_start, port)

    def _try_start(self, port: Port) -> None:
        now = self.sched.now
        if port.killed or not port.queue:
            port._pending = False
            port.queue.clear()
            return
        if self.active and not self._unheard(port.owner, port.queue[0][2] if len(port.queue[0]) > 2 else None):
            first = min(tx.start for tx in self.active)
            driven, port.driven_at = port.driven_at, None
            if (now if driven is None else min(now, driven)) - first >= self.bit_time:
                port._pending = False   # carrier sensed: _finish() reschedules waiting ports
                return
        elif now < self.idle_at + self.turnaround and self.idle_at > 0:
            self.sched.at(self.idle_at + self.turnaround, self._try_start, port)
            return
        port.driven_at = None
        data = port.queue.pop(0)
        tx = Transmission(port, data, now, now + self.frame_time(len(data)))
        if port.muted:
            # a dead transmitter: nothing reaches the line, the station just thinks it sent
            self.sched.at(tx.end, self._muted_done, port)
            return
        if self.active:
            tx.collided = True
            for other in self.active:
                other.collided = True
                other.partners.append(tx)
                tx.partners.append(other)
        else:
            self.busy_since = now
        self.active.append(tx)
        self.sched.at(tx.end, self._finish, tx)

    def _muted_done(self, port: Port) -> None:
        port._pending = False
        if port.queue:
            port._pending = True
            self._schedule_start(port)

    def _finish(self, tx: Transmission) -> None:
        now = self.sched.now
        st = self.stats
        st.frames += 1
        st.bytes += len(tx.data)
        if tx.collided:
            st.collisions += 1
            heard = bytearray(tx.data)
            for other in tx.partners:
                for i, b in enumerate(other.data[: len(heard)]):
                    heard[i] &= b
            heard_b = bytes(heard)
        else:
            heard_b = tx.data
        self.active.remove(tx)
        if not self.active:
            st.busy_s += now - self.busy_since
            self.idle_at = now
        flags: list[str] = ["collision"] if tx.collided else []
        f = self.fault
        if f.corrupt and heard_b and self.rng.random() < f.corrupt:
            i = self.rng.randrange(len(heard_b))
            heard_b = heard_b[:i] + bytes([heard_b[i] ^ (1 << self.rng.randrange(8))]) + heard_b[i + 1:]
            st.corrupted += 1
            flags.append("corrupt")
        lost = bool(f.loss) and self.rng.random() < f.loss
        if lost:
            st.lost += 1
            flags.append("lost")
        delay = f.delay
        if delay:
            st.delayed += 1
            flags.append("delayed")
        if self.trace is not None:
            self.trace(TraceEntry(tx.start, now, self.name, tx.port.owner, tx.data, None if lost else heard_b, tuple(flags)))
        for port in self.ports:
            if port.killed:
                continue
            if port is tx.port:
                if port.echo is not None:
                    port.echo(self.name, now, tx.data, heard_b)
            elif not lost:
                if delay:
                    self.sched.at(now + delay, port.receiver, self.name, now + delay, heard_b)
                else:
                    port.receiver(self.name, now, heard_b)
        # the sender may go on with its queue; stations deferred by carrier sense retry
        tx.port._pending = False
        for port in self.ports:
            if port.queue and not port._pending and not port.killed:
                port._pending = True
                self._schedule_start(port)
