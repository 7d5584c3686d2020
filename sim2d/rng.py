"""Named random streams derived from the scenario seed.

Each consumer draws from its own stream, so adding a sensor or a fault never
changes the numbers another one sees (issue 4). A stable hash (SHA-256) is used
because Python's hash() of str is salted per process.
"""
from __future__ import annotations

import hashlib
import random


def stream(seed: int, name: str) -> random.Random:
    digest = hashlib.sha256(f"{seed}:{name}".encode()).digest()
    return random.Random(int.from_bytes(digest[:8], "big"))
