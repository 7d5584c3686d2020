"""Free text from the spec never reaches generated code unescaped (issue 10, item 2).

A doc, unit, checksum name or enum text with comment terminators, trigraphs,
quotes, backslashes, line breaks, control and non-ASCII characters is accepted
and lands as text: the C still compiles with the strict flags (so nothing reached
the preprocessor) and the Python imports with the exact text in its docstrings
and strings. Text that must be a name (bus names, field names) is refused.
"""
from __future__ import annotations

from pathlib import Path

import pytest

from tests.hostile.spec_harness import M, N, compile_c, generate, import_python, refused_everywhere, replace, spec_copy

OBJ_BOTH_DOC = 'doc: "Both whiskers touched together."}'
# a unit no threshold is compared with (a SET_ALARM limit shares its data's unit, codegen/lint.py _lint_compared)
CURRENT_UNIT = "{name: current, type: uint, bits: 16, unit: mA,"
CRC_NAME = "name: CRC-16/IBM-3740"
SSC_TEXT = 'MALFUNCTION: "Malfunction"'

DOC = "M.ObjBoth.__doc__"

# (id, file, old, new (YAML), Python expression after import, the text it must start with)
ACCEPTED = [
    ("c_comment_injection", M, OBJ_BOTH_DOC, 'doc: "*/ #error injected /*"}', DOC, "*/ #error injected /*"),
    ("triple_quote_and_trailing_backslash", M, OBJ_BOTH_DOC, r'doc: "say \"\"\"hi\"\"\" and end in a backslash \\"}',
     DOC, 'say """hi""" and end in a backslash \\ (seed'),
    ("line_breaks_and_preprocessor", M, OBJ_BOTH_DOC, r'doc: "one\n#define ARACHNAE_H 1\r\n#error two\\\n"}',
     DOC, "one\n#define ARACHNAE_H 1\r\n#error two\\\n"),
    ("trigraph_splice", M, OBJ_BOTH_DOC, r'doc: "a *??/\n/ #error after splice ??= ??("}', DOC, "a *??/\n/ #error after splice ??= ??("),
    ("control_and_non_ascii", M, OBJ_BOTH_DOC, r'doc: "30 \u00b0C\t\0\x1b[2J \u2028 \U0001F577"}',
     DOC, "30 \u00b0C\t\0\x1b[2J \u2028 \U0001F577"),
    ("jinja_looking_text", M, OBJ_BOTH_DOC, 'doc: "{{ spec.hash }} {% raw %} {#"}', DOC, "{{ spec.hash }} {% raw %} {#"),
    ("unit_with_quotes_and_terminators", M, CURRENT_UNIT, r'{name: current, type: uint, bits: 16, unit: "*/ \"mA\" \\",',
     "next(f.unit for f in M.JointFeedback.FIELDS if f.name == 'current')", '*/ "mA" \\'),
    ("checksum_name", M, CRC_NAME, r'name: "CRC \" */ \\"', "__import__('arachnae_proto.frame').frame.CRC_NAME", 'CRC " */ \\'),
    ("enum_text", M, SSC_TEXT, r'MALFUNCTION: "\"\"\" \\"',
     "__import__('arachnae_proto.enums').enums.SSC_MESSAGE_TEXTS[1]", '""" \\'),
]


@pytest.mark.parametrize("case", ACCEPTED, ids=[c[0] for c in ACCEPTED])
def test_hostile_text_is_escaped_where_it_lands(tmp_path: Path, case) -> None:
    _id, file, old, new, expr, text = case
    spec_dir = spec_copy(tmp_path)
    replace(spec_dir, file, old, new)
    out = tmp_path / "generated"
    generate(spec_dir, out)
    compile_c(out / "c", syntax_only=_id != "c_comment_injection", work=tmp_path)
    import_python(out / "python", f"from arachnae_proto import messages as M\nassert ({expr}).startswith({text!r}), {expr}\n")


def test_injected_text_stays_inside_its_comment(tmp_path: Path) -> None:
    spec_dir = spec_copy(tmp_path)
    replace(spec_dir, M, OBJ_BOTH_DOC, 'doc: "*/ #error injected /*"}')
    generate(spec_dir, tmp_path / "generated")
    line = next(t for t in (tmp_path / "generated" / "c" / "msg_obj_both.c").read_text().splitlines() if "injected" in t)
    assert line.startswith("/* ") and line.endswith(" */") and line.count("*/") == 1, line


REFUSED = [
    ("lone_surrogate", M, OBJ_BOTH_DOC, r'doc: "half a pair \ud800"}', "contains a lone surrogate, not text"),
    ("bus_name_with_quote", N, "  sensor:  {long:", '  "sen\\"sor": {long:', "buses: 'sen\"sor' does not match"),
    ("bus_name_with_newline", N, "  sensor:  {long:", '  "sen\\nsor": {long:', "'sen\\nsor' does not match"),
    ("field_name_with_terminator", M, "{name: line, type: uint", '{name: "x*/", type: uint', "'x*/' does not match"),
    ("role_with_space", M, "from: [NP3, UIC_RCP]", 'from: [NP3, "UIC RCP"]', "'UIC RCP' does not match"),
]


@pytest.mark.parametrize("case", REFUSED, ids=[c[0] for c in REFUSED])
def test_text_where_a_name_belongs_is_refused(tmp_path: Path, case) -> None:
    _id, file, old, new, expect = case
    spec_dir = spec_copy(tmp_path)
    replace(spec_dir, file, old, new)
    refused_everywhere(tmp_path, spec_dir, file, expect)
