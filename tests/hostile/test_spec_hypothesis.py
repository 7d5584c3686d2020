"""Spec mutations, hostile strings and names included: `spec check` refuses with file:line, or the
generated C compiles with the strict flags and the generated Python imports (issue 10, item 2).

Derandomised and bounded so it runs in CI; `pytest -s` prints the counts.
"""
from __future__ import annotations

import copy
import math
import re
import tempfile
from pathlib import Path
from typing import Any

import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from arachnae.errors import UserError
from codegen.generate import render, write
from codegen.load import load_spec
from tests.hostile.spec_harness import SPEC, M, N, compile_c, import_python

HOSTILE_TEXT = ["*/ #error injected /*", '"""', "ends in a backslash \\", "*??/", "one\n#define X\n", "\r\x00\x1b[2J",
                "30 \u00b0C \u2713 \U0001F577", "{{ spec }}{% raw %}", "", "x" * 3000, "'\"", "\u2028", "a\\"]
HOSTILE_NAMES = ["class", "int", "self", "len", "NONE", "BASE", "MESSAGE", "LCP_1", "A__B", "_X", "x", "IF", "linux",
                 "encode", "ARACHNAE", "None", "1ABC", "A-B", "\u00c4", "OBJ_LEFT", "UNHANDLED", "VALUE_ERROR", "match",
                 "MASK", "MAX_SIZE", "uint8_t", "on_unhandled", "NULL", "EOF", "__init__"]
HOSTILE_NUMBERS = [math.nan, math.inf, -math.inf, 2.0, 1.0, True, False, -1, 0, 2 ** 70, "1/0", "1.5/2", "-10/255", "0/5",
                   1e-300, 1e300, 255, 256, 65536, "1/3", 0.1]
STATS = {"tried": 0, "refused": 0, "accepted_and_built": 0}


def _docs() -> dict[str, Any]:
    return {name: yaml.safe_load((SPEC / name).read_text(encoding="utf-8")) for name in (N, M)}


DOCS = _docs()


def _leaves(node: Any, path: tuple = ()) -> list[tuple]:
    if isinstance(node, dict):
        return [p for k, v in node.items() for p in _leaves(v, path + (k,))]
    if isinstance(node, list):
        return [p for i, v in enumerate(node) for p in _leaves(v, path + (i,))]
    return [path]


LEAVES = [(name, path) for name, doc in DOCS.items() for path in _leaves(doc)]
TEXT_LEAVES = [(n, p) for n, p in LEAVES if p[-1] in ("doc", "unit", "long", "rule", "when") or "texts" in p
               or p == ("frame", "checksum", "name")]
NAMES = sorted({m["name"] for m in DOCS[M]["messages"]} | {f["name"] for m in DOCS[M]["messages"] for f in m.get("fields", [])}
               | set(DOCS[M]["enums"]) | set(DOCS[M]["flags"]) | {k for e in DOCS[M]["enums"].values() for k in e.get("values", e.get("names", []))}
               | {n["role"] for n in DOCS[N]["nodes"]} | {n["short"] for n in DOCS[N]["nodes"]} | set(DOCS[N]["buses"]))


def _set(docs: dict, file: str, path: tuple, value: Any) -> None:
    node = docs[file]
    for step in path[:-1]:
        node = node[step]
    node[path[-1]] = value


def _rename(texts: dict[str, str], old: str, new: str) -> None:
    for file in texts:
        texts[file] = re.sub(rf"(?<![\w(]){re.escape(old)}(?![\w(])", new.replace("\\", r"\\"), texts[file])


structural = st.tuples(st.just("set"), st.sampled_from(LEAVES), st.sampled_from(HOSTILE_TEXT + HOSTILE_NAMES + HOSTILE_NUMBERS))
textual = st.tuples(st.just("set"), st.sampled_from(TEXT_LEAVES), st.sampled_from(HOSTILE_TEXT))
renaming = st.tuples(st.just("rename"), st.sampled_from(NAMES), st.sampled_from(HOSTILE_NAMES))
mutations = st.lists(st.one_of(structural, textual, textual, renaming), min_size=1, max_size=2)


def _apply(folder: Path, steps: list[tuple]) -> None:
    docs = copy.deepcopy(DOCS)
    sets = [s for s in steps if s[0] == "set"]
    for _kind, (file, path), value in sets:
        _set(docs, file, path, value)
    texts = {name: (yaml.safe_dump(docs[name], allow_unicode=True, sort_keys=False, width=10_000) if sets
                    else (SPEC / name).read_text(encoding="utf-8")) for name in (N, M)}
    for _kind, old, new in (s for s in steps if s[0] == "rename"):
        _rename(texts, old, new)
    for name, text in texts.items():
        (folder / name).write_text(text, encoding="utf-8")


@settings(derandomize=True, max_examples=45, deadline=None, database=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(mutations)
def test_mutated_spec_is_refused_at_a_line_or_builds(steps) -> None:
    STATS["tried"] += 1
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp) / "spec"
        folder.mkdir()
        _apply(folder, steps)
        try:
            spec = load_spec(folder)
        except UserError as err:
            STATS["refused"] += 1
            where = re.compile(rf"^{re.escape(str(folder))}/(nodes|messages)\.yaml:\d+: \S")
            bad = [line for line in str(err).splitlines() if not where.match(line)]
            assert not bad, f"{steps}: not file:line: {bad}"
            return
        out = Path(tmp) / "generated"
        write(render(spec), out)
        compile_c(out / "c", work=Path(tmp))
        import_python(out / "python")
        STATS["accepted_and_built"] += 1


def teardown_module() -> None:
    print(f"\nhostile spec mutations: {STATS['tried']} tried, {STATS['refused']} refused at file:line, "
          f"{STATS['accepted_and_built']} accepted and built; 0 tracebacks, 0 silent acceptances (else the test failed)")
