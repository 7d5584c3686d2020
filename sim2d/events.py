"""A discrete-event scheduler: a heap of (time, sequence, callback).

The sequence number breaks ties in insertion order, which keeps runs
deterministic for a given seed.
"""
from __future__ import annotations

import heapq
from typing import Any, Callable


class Scheduler:
    def __init__(self) -> None:
        self.now = 0.0
        self._heap: list[tuple[float, int, Callable[..., Any], tuple]] = []
        self._seq = 0

    def at(self, t: float, fn: Callable[..., Any], *args: Any) -> None:
        if t < self.now:
            t = self.now
        heapq.heappush(self._heap, (t, self._seq, fn, args))
        self._seq += 1

    def after(self, delay: float, fn: Callable[..., Any], *args: Any) -> None:
        self.at(self.now + delay, fn, *args)

    def run_until(self, t_end: float) -> None:
        heap = self._heap
        while heap and heap[0][0] <= t_end:
            t, _, fn, args = heapq.heappop(heap)
            self.now = t
            fn(*args)
        self.now = max(self.now, t_end)

    def pending(self) -> int:
        return len(self._heap)
