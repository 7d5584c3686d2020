"""A test bench for one behaviour: its board, a perfect bus, and scripted peers.

Everything the node sends is parsed from its bytes (arachnae_proto.frame),
echoed back cleanly after its time on the line, and answered by `respond`
(a function Frame -> list of (src, message)) one turnaround later. No sim2d.
"""
from __future__ import annotations

import heapq
from typing import Any, Callable

from arachnae_proto.frame import Frame, build, parse
from arachnae_proto.messages import Message
from arachnae_proto.network import ROUTES

from behaviours import behaviour_class
from behaviours.geometry import DEFAULT_GEOMETRY
from behaviours.hardware import ServoState
from behaviours.netconfig import Config, NetConfig
from behaviours.runtime import BusTiming

Respond = Callable[[Frame], list]


class Board:
    """behaviours.hardware.Hardware for tests: a heap clock, line state, settable sensors."""

    def __init__(self) -> None:
        self.t = 0.0
        self._heap: list = []
        self._seq = 0
        self.busy_until: dict[str, float] = {}
        self.notes: list[tuple[float, str, dict]] = []
        self.sole = True
        self.whisker = (False, False)
        self.sonar: list = []             # readings returned in turn: (metres or None, tof)
        self.servo = ServoState(0.0, 0.0, 0.05, 20.0)
        self.servo_set: list[tuple[float, float | None]] = []   # (time, speed command) the JAC gave the servo

    def now(self) -> float:
        return self.t

    def after(self, delay: float, fn: Callable[..., Any], *args: Any) -> None:
        heapq.heappush(self._heap, (self.t + delay, self._seq, fn, args))
        self._seq += 1

    def run(self, until: float) -> None:
        while self._heap and self._heap[0][0] <= until:
            t, _, fn, args = heapq.heappop(self._heap)
            self.t = t
            fn(*args)
        self.t = until

    def line_idle_s(self, bus: str) -> float:
        end = self.busy_until.get(bus, 0.0)
        return 0.0 if self.t < end else self.t - end + 1.0   # + 1 s: idle since long before

    def note(self, event: str, **data: Any) -> None:
        self.notes.append((self.t, event, data))

    def sole_contact(self) -> bool:
        return self.sole

    def whiskers(self) -> tuple[bool, bool]:
        return self.whisker

    def sonar_ping(self, head_deg: int) -> tuple[float | None, float]:
        return self.sonar.pop(0) if self.sonar else (None, 0.06)

    def set_servo_drive(self, speed: float | None) -> None:
        self.servo_set.append((self.t, speed))

    def servo_state(self) -> ServoState:
        return self.servo


class Rig:
    def __init__(self, spec: Any, role: str, address: int, respond: Respond | None = None, task: str = "forward") -> None:
        self.board = Board()
        self.respond = respond or (lambda f: [])
        self.sent: list[tuple[float, str, Frame]] = []
        self.garble: Callable[[Frame], bool] = lambda f: False   # True: that frame collides (corrupt echo, no reply)
        cfg = Config(NetConfig.from_spec(spec), DEFAULT_GEOMETRY, task)
        self.node = behaviour_class(role)(address, self._transmit, self.board, cfg)
        self.node.start()

    def _transmit(self, bus: str, data: bytes) -> None:
        b, t = self.board, BusTiming(bus)
        frame = parse(data)                                   # the node put valid bytes on the wire
        self.sent.append((b.t, bus, frame))
        end = max(b.t, b.busy_until.get(bus, 0.0)) + len(data) * t.char_s
        b.busy_until[bus] = end
        if self.garble(frame):
            b.after(end - b.t, self.node.on_echo, bus, data, data[:-1] + bytes([data[-1] ^ 0xFF]))
            return
        b.after(end - b.t, self.node.on_echo, bus, data, data)
        start = end + t.turnaround_s
        for src, msg in self.respond(frame):
            reply = build(self.node.address, src, msg)
            start_reply = start
            end_reply = start_reply + len(reply) * t.char_s
            b.after(start_reply - b.t, self._line, bus, end_reply)
            b.after(end_reply - b.t, self.node.receive, bus, reply)
            start = end_reply + t.turnaround_s

    def _line(self, bus: str, until: float) -> None:
        self.board.busy_until[bus] = max(self.board.busy_until.get(bus, 0.0), until)

    def inject(self, at: float, src: int, msg: Message) -> None:
        """`src` sends `msg` to the node at time `at` (bytes, on the bus they share)."""
        bus = ROUTES[src][self.node.address]
        self.board.after(at - self.board.t, self.node.receive, bus, build(self.node.address, src, msg))

    def run(self, until: float) -> None:
        self.board.run(until)

    def frames(self, cls: type, dst: int | None = None) -> list[tuple[float, Frame]]:
        return [(t, f) for t, _b, f in self.sent if type(f.message) is cls and (dst is None or f.dst == dst)]
