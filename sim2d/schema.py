"""A small schema checker over PyYAML nodes, so every error can name its line.

Validating the composed node tree (not the loaded dict) keeps each value's
start mark; a mistake becomes `file:line: message` via arachnae.errors.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, Mapping, Sequence

import yaml

from arachnae.errors import UserError, located


@dataclass(frozen=True)
class Src:
    """Where a node came from: the file path (the node carries its own line)."""

    path: str


def fail(src: Src, node: yaml.Node | None, message: str) -> UserError:
    line = node.start_mark.line + 1 if node is not None else None
    return UserError(located(src.path, line, message))


class Schema:
    """A validator: turns a yaml node into a Python value or raises UserError."""

    def __call__(self, src: Src, node: yaml.Node, what: str) -> Any:  # pragma: no cover - abstract
        raise NotImplementedError


def _scalar(src: Src, node: yaml.Node, what: str) -> Any:
    if not isinstance(node, yaml.ScalarNode):
        raise fail(src, node, f"{what}: expected a single value")
    return _construct(node)


def _construct(node: yaml.ScalarNode) -> Any:
    loader = yaml.SafeLoader("")
    try:
        return loader.construct_object(node, deep=True)
    finally:
        loader.dispose()


class Num(Schema):
    def __init__(self, lo: float | None = None, hi: float | None = None, integer: bool = False, positive: bool = False):
        self.lo, self.hi, self.integer, self.positive = lo, hi, integer, positive

    def __call__(self, src: Src, node: yaml.Node, what: str) -> float | int:
        v = _scalar(src, node, what)
        kind = "an integer" if self.integer else "a number"
        if isinstance(v, bool) or not isinstance(v, (int, float)) or (self.integer and not isinstance(v, int)):
            raise fail(src, node, f"{what}: expected {kind}, got {node.value!r}")
        if v != v or v in (float("inf"), float("-inf")):
            raise fail(src, node, f"{what}: expected a finite number")
        if self.positive and v <= 0:
            raise fail(src, node, f"{what}: must be > 0, got {v}")
        if self.lo is not None and v < self.lo:
            raise fail(src, node, f"{what}: must be >= {self.lo}, got {v}")
        if self.hi is not None and v > self.hi:
            raise fail(src, node, f"{what}: must be <= {self.hi}, got {v}")
        return v if self.integer else float(v)


class Bool(Schema):
    def __call__(self, src: Src, node: yaml.Node, what: str) -> bool:
        v = _scalar(src, node, what)
        if not isinstance(v, bool):
            raise fail(src, node, f"{what}: expected true or false, got {node.value!r}")
        return v


class Str(Schema):
    def __init__(self, choices: Sequence[str] | None = None, check: Callable[[str], str | None] | None = None):
        self.choices, self.check = choices, check

    def __call__(self, src: Src, node: yaml.Node, what: str) -> str:
        v = _scalar(src, node, what)
        if not isinstance(v, str):
            v = str(node.value)
        if self.choices is not None and v not in self.choices:
            raise fail(src, node, f"{what}: {v!r} is not one of {', '.join(self.choices)}")
        if self.check is not None:
            problem = self.check(v)
            if problem:
                raise fail(src, node, f"{what}: {problem}")
        return v


class List(Schema):
    def __init__(self, item: Schema, min_len: int = 0):
        self.item, self.min_len = item, min_len

    def __call__(self, src: Src, node: yaml.Node, what: str) -> list:
        if not isinstance(node, yaml.SequenceNode):
            raise fail(src, node, f"{what}: expected a list")
        if len(node.value) < self.min_len:
            raise fail(src, node, f"{what}: needs at least {self.min_len} entries, got {len(node.value)}")
        return [self.item(src, n, f"{what}[{i}]") for i, n in enumerate(node.value)]


class Scalar(Schema):
    """Any single value (a number, a string, true/false)."""

    def __call__(self, src: Src, node: yaml.Node, what: str) -> Any:
        return _scalar(src, node, what)


class Dict(Schema):
    """A mapping from free-form string keys to values of one schema."""

    def __init__(self, value: Schema):
        self.value = value

    def __call__(self, src: Src, node: yaml.Node, what: str) -> dict:
        if not isinstance(node, yaml.MappingNode):
            raise fail(src, node, f"{what}: expected a mapping")
        return {str(k.value): self.value(src, v, f"{what}.{k.value}") for k, v in node.value}


class Point(Schema):
    def __call__(self, src: Src, node: yaml.Node, what: str) -> tuple[float, float]:
        if not isinstance(node, yaml.SequenceNode) or len(node.value) != 2:
            raise fail(src, node, f"{what}: expected a point [x, y]")
        return (Num()(src, node.value[0], what), Num()(src, node.value[1], what))


class Polygon(Schema):
    """At least 3 distinct vertices with a non-zero area (pymunk needs that)."""

    def __call__(self, src: Src, node: yaml.Node, what: str) -> tuple[tuple[float, float], ...]:
        pts = List(Point(), 3)(src, node, what)
        area2 = sum(pts[i - 1][0] * p[1] - p[0] * pts[i - 1][1] for i, p in enumerate(pts))
        if abs(area2) < 1e-9:
            raise fail(src, node, f"{what}: polygon has no area")
        return tuple(pts)


@dataclass
class Key:
    schema: Schema
    required: bool = False
    default: Any = None


class Map(Schema):
    def __init__(self, keys: Mapping[str, Key], check: Callable[[dict], str | None] | None = None):
        self.keys, self.check = keys, check

    def __call__(self, src: Src, node: yaml.Node, what: str) -> dict:
        if not isinstance(node, yaml.MappingNode):
            raise fail(src, node, f"{what}: expected a mapping")
        return self.convert([(src, k, v) for k, v in node.value], src, node, what)

    def convert(self, items: list[tuple[Src, yaml.Node, yaml.Node]], src: Src, node: yaml.Node, what: str) -> dict:
        """Validate key/value node pairs, possibly gathered from several files."""
        out: dict[str, Any] = {}
        seen: dict[str, yaml.Node] = {}
        for s, k, v in items:
            name = str(k.value)
            if name not in self.keys:
                raise fail(s, k, f"{what}: unknown key {name!r} (expected one of {', '.join(self.keys)})")
            seen[name] = k
            out[name] = self.keys[name].schema(s, v, f"{what}.{name}" if what else name)
        for name, key in self.keys.items():
            if name not in out:
                if key.required:
                    raise fail(src, node, f"{what or 'scenario'}: missing required key {name!r}")
                out[name] = key.default
        if self.check is not None:
            problem = self.check(out)
            if problem:
                raise fail(src, node, f"{what}: {problem}")
        return out
