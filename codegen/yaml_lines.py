"""YAML loading that remembers where every value came from.

Diagnostics must name `file:line`, and PyYAML forgets positions once it builds
plain dicts; it also silently keeps the last of two equal keys. This loader
keeps a line per key and per list item and rejects duplicate keys.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml

from arachnae.errors import UserError, located


class LDict(dict):
    """A dict with the line of the mapping and of each key."""

    line: int = 0
    key_lines: dict[str, int]


class LList(list):
    """A list with the line of the sequence and of each item."""

    line: int = 0
    item_lines: list[int]


class _Loader(yaml.SafeLoader):
    pass


def _construct_mapping(loader: _Loader, node: yaml.MappingNode) -> LDict:
    result = LDict()
    result.line = node.start_mark.line + 1
    result.key_lines = {}
    loader.flatten_mapping(node)
    for key_node, value_node in node.value:
        key = loader.construct_object(key_node, deep=True)
        if key in result.key_lines:
            raise yaml.MarkedYAMLError(problem=f"duplicate key '{key}'", problem_mark=key_node.start_mark)
        result[key] = loader.construct_object(value_node, deep=True)
        result.key_lines[key] = key_node.start_mark.line + 1
    return result


def _construct_sequence(loader: _Loader, node: yaml.SequenceNode) -> LList:
    result = LList(loader.construct_object(child, deep=True) for child in node.value)
    result.line = node.start_mark.line + 1
    result.item_lines = [child.start_mark.line + 1 for child in node.value]
    return result


_Loader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, _construct_mapping)
_Loader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_SEQUENCE_TAG, _construct_sequence)


def load_yaml(path: Path) -> Any:
    """Parse one YAML file; a syntax error or duplicate key becomes a one-line UserError."""
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise UserError(located(str(path), None, f"cannot read: {exc.strerror}")) from None
    try:
        return yaml.load(text, Loader=_Loader)  # noqa: S506 - _Loader derives from SafeLoader
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line = mark.line + 1 if mark else None
        problem = exc.problem or exc.context or "invalid YAML"
        raise UserError(located(str(path), line, problem)) from None
    except yaml.YAMLError as exc:
        raise UserError(located(str(path), None, str(exc).splitlines()[0])) from None


def line_of(doc: Any, path: list[Any] | tuple[Any, ...]) -> int | None:
    """The line of the value at `path` (keys and indices), or of its nearest ancestor."""
    line = getattr(doc, "line", None)
    node = doc
    for step in path:
        if isinstance(node, LDict) and step in node:
            line = node.key_lines.get(step, line)
        elif isinstance(node, LList) and isinstance(step, int) and 0 <= step < len(node):
            line = node.item_lines[step]
        else:
            break
        node = node[step]
    return line
