"""A discrete-event scheduler: a heap of (time, sequence, callback).

The sequence number breaks ties in insertion order, which keeps runs
deterministic for a given seed.
"""
from __future__ import annotations

import itertools
from heapq import heappop, heappush
from typing import Any, Callable


class Scheduler:
    def __init__(self) -> None:
        self.now = 0.0
        self._heap: list[tuple[float, int, Callable[..., Any], tuple]] = []
        self._seq = itertools.count()

    def at(self, t: float, fn: Callable[..., Any], *args: Any) -> None:
        if t < self.now:
            t = self.now
        heappush(self._heap, (t, next(self._seq), fn, args))

    def after(self, delay: float, fn: Callable[..., Any], *args: Any) -> None:
        """`at(now + delay, ...)`, one call less: every node timer comes through here (NodeHardware.after)."""
        now = self.now
        t = now + delay
        heappush(self._heap, (t if t >= now else now, next(self._seq), fn, args))

    def run_until(self, t_end: float) -> None:
        heap = self._heap
        while heap and heap[0][0] <= t_end:
            t, _, fn, args = heappop(heap)
            self.now = t
            fn(*args)
        self.now = max(self.now, t_end)

    def pending(self) -> int:
        return len(self._heap)
