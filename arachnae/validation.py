"""JSON Schema over the line-tracking documents of arachnae.yamlio, with one-line `file:line: field: problem` errors.

Why: structure is declared once as a schema (the spec in codegen/schema/, scenarios in
sim2d/scenario.schema.yaml, sweeps in sim2d/sweep.schema.yaml) instead of being hand-coded,
and every violation still names the file and line it came from. `Validator` is the one
JSON Schema validator of the toolkit (the spec's lint uses it too). A schema may give a
friendlier text per keyword with `x-messages: {keyword: text}`.
"""
from __future__ import annotations

from typing import Any, Iterator, Sequence

import math

import jsonschema
from jsonschema import validators

from arachnae.errors import UserError
from arachnae.yamlio import LDict, LList, locate, where

def _is_integer(_checker: Any, value: Any) -> bool:
    """An int, never a bool (YAML's true is an int in Python) and never a float such as 2.0: a float where a
    count, address or seed is meant is a mistake (issue 10, item 3)."""
    return isinstance(value, int) and not isinstance(value, bool)


def _is_number(_checker: Any, value: Any) -> bool:
    """A finite int or float: NaN and infinity are no value a spec or scenario can mean."""
    return _is_integer(_checker, value) or isinstance(value, float) and math.isfinite(value)


Validator = validators.extend(jsonschema.Draft202012Validator, type_checker=jsonschema.Draft202012Validator.TYPE_CHECKER
                              .redefine_many({"integer": _is_integer, "number": _is_number}))

_TYPE_WORDS = {"number": "a number", "integer": "an integer", "array": "a list", "object": "a mapping",
               "boolean": "true or false", "string": "text", "null": "nothing"}


def field_name(path: Sequence[Any]) -> str:
    """`lights[0].intensity` from ['lights', 0, 'intensity']."""
    out = ""
    for step in path:
        out += f"[{step}]" if isinstance(step, int) else (f".{step}" if out else str(step))
    return out


def _shown(value: Any) -> str:
    if isinstance(value, dict):
        return "a mapping"
    if isinstance(value, list):
        return "a list"
    return repr(value)


def _problem(err: jsonschema.ValidationError) -> tuple[list[Any], str]:
    """(path to point at, message) for one schema violation: the one wording of the spec's lint, the scenarios and
    the sweeps. A schema's `description` of a value names what was expected when its type or pattern does not fit."""
    path = list(err.absolute_path)
    schema = err.schema if isinstance(err.schema, dict) else {}
    custom = (schema.get("x-messages") or {}).get(err.validator)
    if custom:
        return path, custom
    v, inst = err.validator_value, err.instance
    if err.validator in ("type", "pattern") and "description" in schema:
        return path, f"expected {schema['description']}, got {_shown(inst)}"
    if err.validator == "type":
        kinds = v if isinstance(v, list) else [v]
        return path, f"expected {' or '.join(_TYPE_WORDS.get(k, k) for k in kinds)}, got {_shown(inst)}"
    if err.validator == "enum":
        return path, f"{inst!r} is not one of {', '.join(map(str, v))}"
    limits = {"minimum": ">=", "exclusiveMinimum": ">", "maximum": "<=", "exclusiveMaximum": "<"}
    if err.validator in limits:
        return path, f"must be {limits[err.validator]} {v}, got {inst}"
    if err.validator == "required":         # jsonschema reports each missing key alone: name them all, once
        missing = [k for k in v if k not in inst]
        return path, f"missing required key{'s' if len(missing) > 1 else ''} {', '.join(map(repr, missing))}"
    if err.validator == "additionalProperties":
        known = list(err.schema.get("properties", {}))
        extra = next(k for k in inst if k not in known)
        expected = f" (expected one of {', '.join(known)})" if known else ""
        return path + [extra], f"unknown key {extra!r}{expected}"
    if err.validator == "minItems":
        return path, f"needs at least {v} entries, got {len(inst)}"
    if err.validator == "maxItems":
        return path, f"takes at most {v} entries, got {len(inst)}"
    return path, err.message


def schema_errors(doc: Any, schema: dict[str, Any]) -> Iterator[UserError]:
    """One one-line UserError (`file:line: field: problem`) per field that breaks the schema, its first problem,
    in document order."""
    errors: dict[str, tuple[str, int, UserError]] = {}
    for err in Validator(schema).iter_errors(doc):
        path, message = _problem(err)
        what = field_name(path) or "(top level)"
        file, line = where(doc, path)
        errors.setdefault(what, (file, line or 0, locate(doc, path, f"{what}: {message}")))
    for _f, _l, exc in sorted(errors.values(), key=lambda e: (e[0], e[1])):
        yield exc


def check_schema(doc: Any, schema: dict[str, Any]) -> None:
    """Raise the first violation (one line, `file:line: field: problem`)."""
    for exc in schema_errors(doc, schema):
        raise exc


def fill_defaults(doc: Any, schema: dict[str, Any], root: dict[str, Any] | None = None) -> None:
    """Set each absent key that the schema gives a `default:` (in place; lines point at the enclosing mapping)."""
    root = schema if root is None else root
    while "$ref" in schema:                      # local references only ("#/$defs/name")
        schema = root["$defs"][schema["$ref"].rsplit("/", 1)[1]] | {k: v for k, v in schema.items() if k != "$ref"}
    if isinstance(doc, LDict):
        for key, sub in schema.get("properties", {}).items():
            if key not in doc and "default" in sub:
                default = sub["default"]
                doc.put(key, list(default) if isinstance(default, list) else default, doc.line, doc.path)
            if key in doc:
                fill_defaults(doc[key], sub, root)
    elif isinstance(doc, LList) and isinstance(schema.get("items"), dict):
        for item in doc:
            fill_defaults(item, schema["items"], root)
