"""`arachnae spec check` names the file and line of every deliberately broken spec.

Each case copies the real spec, breaks it in one place, and expects one exact
diagnostic at the line where the problem is.
"""
from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from arachnae.errors import UserError
from codegen.model import SPEC_DIR
from codegen.load import load_spec

N, M = "nodes.yaml", "messages.yaml"

# (id, file, text to replace, replacement, text on the line the diagnostic names (None: the replacement), message)
CASES = [
    ("duplicate_address", N, "address: 0x02, level: 0, role: NP3", "address: 0x01, level: 0, role: NP3", None,
     "NP3: duplicate address 0x01, already used by MCP"),
    ("broadcast_as_node", N, "address: 0x08, level: 0, role: RLC", "address: 0xFF, level: 7, role: RLC", None,
     "RLC: address 0xFF is the broadcast address (seed 3.2.1)"),
    ("level_mismatch", N, "address: 0x27, level: 1, role: USRC", "address: 0x27, level: 2, role: USRC", None,
     "USRC: level 2 does not match address 0x27 (top bits say 1)"),
    ("unknown_bus", N, "role: USRC, bus: sensor,", "role: USRC, bus: sensr,", None, "USRC: unknown bus 'sensr'"),
    ("unknown_master", N, "master: MMC, baud: 19200", "master: MMX, baud: 19200", None, "bus leg: unknown master node 'MMX'"),
    ("duplicate_yaml_key", N, "  leg:     {long:", "  first:   {long:", '  first:   {long: "MMC', "duplicate key 'first'"),
    ("missing_key", N, 'role: NP3, bus: first, status: required, section: "3.2.3"', 'role: NP3, bus: first, section: "3.2.3"', None,
     "nodes[1]: missing required key 'status'"),
    ("missing_keys_in_one_line", N, 'role: NP3, bus: first, status: required, section: "3.2.3"', 'bus: first, section: "3.2.3"',
     None, "nodes[1]: missing required keys 'role', 'status'"),
    ("bad_status", N, "role: SSC, bus: first, status: optional", "role: SSC, bus: first, status: maybe", None,
     "nodes[4].status: 'maybe' is not one of required, optional"),
    ("yaml_syntax", N, '{short: SPU, long: "Sensor Processing Unit",', '{short: SPU, long: "Sensor Processing Unit",,', None,
     "expected"),
    ("quorum_too_big", N, "min_complete: 5", "min_complete: 7", None, "quorum legs: needs 7 units but only 6 exist"),
    ("duplicate_opcode", M, "name: MOVE\n    opcode: 0x21", "name: MOVE\n    opcode: 0x20", None,
     "MOVE: duplicate opcode 0x20, already used by DATA"),
    ("field_wider_than_bits", M, "{name: angle, type: uint, bits: 16, unit: deg, range: [0, 359]}",
     "{name: angle, type: uint, bits: 8, unit: deg, range: [0, 359]}", None,
     "HEAD_SET_ABS.angle: range [0, 359] deg needs raw 0..359, but 8 bits hold 0..255"),
    ("range_encoding_cannot_hold", M, 'unit: m, scale: "10/255", range: [0, 10]}', 'unit: m, scale: "10/255", range: [0, 11]}', None,
     "XMIT_DATA_USRC.distance: range [0, 11] m needs raw 0..281, but 8 bits hold 0..255"),
    ("signed_range", M, "{name: longitudinal, type: int, bits: 8, unit: deg, range: [-60, 60]}",
     "{name: longitudinal, type: int, bits: 8, unit: deg, range: [-200, 60]}", None,
     "XMIT_DATA_ISC.longitudinal: range [-200, 60] deg needs raw -200..60, but 8 signed bits hold -128..127"),
    ("unknown_enum", M, "{name: mov_cmd, type: enum, enum: MOV_CMD, bits: 4}\n      - {name: param, type: uint, bits: 4, range: [0, 0], doc",
     "{name: mov_cmd, type: enum, enum: MOVE_CMD, bits: 4}\n      - {name: param, type: uint, bits: 4, range: [0, 0], doc",
     "enum: MOVE_CMD", "MOVE.mov_cmd: unknown enum 'MOVE_CMD'"),
    ("enum_wider_than_field", M, "LCP_OUT_OF_ORDER: 4, NO_GROUND: 5}", "LCP_OUT_OF_ORDER: 4, NO_GROUND: 5, OTHER: 16}",
     "{name: error, type: enum, enum: MMC_ERROR, bits: 4}", "STATUS_ACK_MMC.error: enum MMC_ERROR has value 16, wider than 4 bits"),
    ("unknown_role", M, "from: [NP3, UIC_RCP]", "from: [NP3, UIC_RPC]", None, "MOVE: unknown node role 'UIC_RPC' in `from`"),
    ("not_on_one_bus", M, "    from: [USRC]\n    to: [SPU]", "    from: [USRC]\n    to: [MCP]", None,
     "XMIT_DATA_USRC: MCP and USRC are not on one bus (docs/decisions.md D2: masters relay between layers)"),
    ("unknown_count_field", M, "{name: missing, type: node, count: missing_count}", "{name: missing, type: node, count: missing_cnt}", None,
     "POST_REPORT.missing: count refers to 'missing_cnt', which is not an earlier field"),
    ("checksum_check_value", M, "check: 0x29B1", "check: 0x29B2", None,
     "checksum CRC-16/IBM-3740: check value 0x29B2 does not match the parameters (they give 0x29B1)"),
    ("payload_too_big", M, "range: [1, 253]}", "range: [1, 254]}", "  - name: SPEAK\n",
     "SPEAK: payload of up to 256 bytes exceeds the frame's max_payload 255"),
    ("array_not_last", M, "      - {name: text, type: char, count: length}\n  - name: SPEAK_RESIDENT",
     "      - {name: text, type: char, count: length}\n      - {name: tail, type: uint, bits: 8}\n  - name: SPEAK_RESIDENT",
     "range: [1, 253]}\n      - {name: text, type: char, count: length}", "SPEAK.text: an array must be the last field"),
    ("priority_not_a_requester", N, "priority: [TPSC, IRRC]", "priority: [TPSC, SPU]", None,
     "bus sensor: priority names SPU, which does not send DATA_RDY on it"),
    ("reflex_unknown_node", N, "    source: TPSC\n", "    source: TPSX\n", "  - name: whisker_stop",
     "reflex whisker_stop: unknown node(s) TPSX"),
    ("reflex_wrong_message", N, "    message: MOVE_RELAYED\n", "    message: MOVE\n", None,
     "reflex whisker_stop: MCP does not send MOVE to MMC"),
    ("reflex_bad_command", N, "    command: STOP\n", "    command: HALT\n", None,
     "reflex whisker_stop: command HALT is no enum value"),
    # issue 16: records, fetches, enum subsets and serial lines are declared, and checked
    ("no_fetch_message", N, "request_message: XMIT_REQ, fetch_message: XMIT_GRANT,", "request_message: XMIT_REQ,",
     None, "bus first: a bus with a request_message needs a fetch_message"),
    ("fetch_not_to_requesters", N, "fetch_message: XMIT_GRANT,", "fetch_message: XMIT_DATA,", None,
     "bus first: XMIT_DATA is not sent by MCP to every role that requests the line"),
    ("relayed_not_a_record", M, "    record: true\n    relayed_as: MOVE_RELAYED", "    relayed_as: MOVE_RELAYED", None,
     "MOVE: relayed_as is for records (`record: true`)"),
    ("subset_unknown_name", M, "names: [TRIPOD, RIPPLE, WAVE]", "names: [TRIPOD, RIPPLE, WAVY]", None,
     "GAIT: WAVY is not a value of MOV_CMD"),
    ("subset_and_values", M, "    subset_of: MOV_CMD\n    names: [TRIPOD, RIPPLE, WAVE]",
     "    subset_of: MOV_CMD\n    values: {TRIPOD: 7}\n    names: [TRIPOD, RIPPLE, WAVE]", "  GAIT:\n",
     "GAIT: needs either `values` or `subset_of` with `names`"),
    ("line_unknown_node", N, 'node: "UIC/RCP"', 'node: "UIC/RCX"', None, "line rcp: unknown node 'UIC/RCX'"),
    ("reply_to_unknown", M, "    reply_to: POST_QUERY\n", "    reply_to: POST_QUERRY\n", None,
     "POST_REPORT: reply_to unknown message 'POST_QUERRY'"),
    ("reply_from_a_non_receiver", M, "    reply_to: ID_REQ\n", "    reply_to: POST_QUERY\n", None,
     "ID_ACK: NP3, SSC, APU_SDF, UIC_RCP, RLC, USRC, TPSC, IRRC, ISC, TSC, LSC, PSC, JAC do(es) not receive POST_QUERY, "
     "so cannot be on the `from` side of its reply"),
    ("two_replies_of_a_role", M, "    from: [NP3, SPU, SSC, APU_SDF, UIC_RCP, RLC]\n    to: [MCP]",
     "    from: [NP3, SPU, SSC, APU_SDF, UIC_RCP, RLC, MMC]\n    to: [MCP]",
     "name: STATUS_ACK_MMC\n    seed_name: STATUS_ACK\n    reply_to: STATUS_REQ",
     "STATUS_ACK_MMC: MMC already answer(s) STATUS_REQ with STATUS_ACK_BUSY"),
    ("carried_in_unknown", M, "{name: OBJ_BOTH, opcode: 0x50, section: \"3.2.12\", carried_in: XMIT_DATA_TPSC,",
     "{name: OBJ_BOTH, opcode: 0x50, section: \"3.2.12\", carried_in: XMIT_DATA_TPSX,", None,
     "OBJ_BOTH: carried_in unknown message 'XMIT_DATA_TPSX'"),
    ("carried_in_without_its_code", M, "bits: {OBJ_LEFT: 0x10, OBJ_RIGHT: 0x20, OBJ_BOTH: 0x40}",
     "bits: {OBJ_LEFT: 0x10, OBJ_RIGHT: 0x20, BOTH: 0x40}", "carried_in: XMIT_DATA_TPSC, from: [TPSC], to: [SPU], doc: \"Both",
     "OBJ_BOTH: XMIT_DATA_TPSC has no flags bit or enum value named OBJ_BOTH to carry it"),
    # seed 3.2.2, 6.2: which fields a sensor's records carry, and what its SET_ALARM threshold is compared with
    ("record_values_unknown_field", M, "record_values: [left, center, right]", "record_values: [left, centre, right]",
     None, "XMIT_DATA_IRRC: record_values names 'centre', which is no field of it"),
    ("record_value_wider_than_a_byte", M, "record_values: [distance]\n    record_channel: angle",
     "record_values: [distance, angle]", None, "XMIT_DATA_USRC.angle: a record carries one value byte, not a 16-bit uint"),
    ("record_values_of_two_encodings", M, "record_values: [temperature]\n    record_channel: channel\n",
     "record_values: [temperature, channel]\n", None,
     "XMIT_DATA_TSC.channel: encoded unlike temperature; a record's values share one encoding"),
    ("record_channel_unknown", M, "record_channel: angle", "record_channel: heading", None,
     "XMIT_DATA_USRC: record_channel 'heading' is no unsigned integer field of it"),
    ("compared_with_unknown", M, "compared_with: XMIT_DATA_IRRC", "compared_with: XMIT_DATA_IRRX", None,
     "SET_ALARM_IRRC.limit: compared_with 'XMIT_DATA_IRRX', which is no message with record_values"),
    ("compared_with_another_role", M, "[4.2, 5.0], compared_with: XMIT_DATA_PSC", "[4.2, 5.0], compared_with: XMIT_DATA_LSC", None,
     "SET_ALARM_PSC.limit: goes to PSC, but XMIT_DATA_LSC comes from LSC"),
    ("compared_with_another_unit", M, "[4.2, 5.0], compared_with: XMIT_DATA_PSC", "[4.2, 5.0], compared_with: XMIT_DATA_LSC", None,
     "SET_ALARM_PSC.limit: unit 'V', but XMIT_DATA_LSC.brightness is in 'lx'"),
    ("two_thresholds_for_one_data", M, "[4.2, 5.0], compared_with: XMIT_DATA_PSC", "[4.2, 5.0], compared_with: XMIT_DATA_LSC", None,
     "SET_ALARM_PSC.limit: SET_ALARM_LSC already sets the threshold for XMIT_DATA_LSC"),
    ("threshold_beyond_the_data", M, "unit: degC, range: [0, 63], compared_with", "unit: degC, range: [0, 120], compared_with",
     None, "SET_ALARM_TSC.limit: range [0, 120] reaches beyond XMIT_DATA_TSC.temperature's [-20, 100]"),
]


def _broken(tmp_path: Path, file: str, old: str, new: str) -> Path:
    for name in (N, M):
        shutil.copy(SPEC_DIR / name, tmp_path / name)
    target = tmp_path / file
    text = target.read_text()
    assert text.count(old) == 1, f"fixture text not unique in the spec: {old!r}"
    target.write_text(text.replace(old, new))
    return target


def _line_of(path: Path, needle: str) -> int:
    """Line of the last line of the first occurrence of `needle`."""
    text = path.read_text()
    assert needle in text, needle
    return text[: text.index(needle)].count("\n") + 1 + needle.rstrip("\n").count("\n")


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_broken_spec_names_file_and_line(tmp_path: Path, case) -> None:
    _id, file, old, new, locate, message = case
    target = _broken(tmp_path, file, old, new)
    line = _line_of(target, locate if locate is not None else new)
    with pytest.raises(UserError) as err:
        load_spec(tmp_path)
    problems = str(err.value).splitlines()
    expected = f"{target}:{line}: {message}"
    assert any(p.startswith(expected) for p in problems), f"wanted {expected!r}, got {problems}"


def test_real_spec_passes(spec) -> None:
    assert len(spec.nodes) == 39
    assert spec.broadcast == 0xFF


def test_cli_reports_every_problem_without_traceback(tmp_path: Path) -> None:
    target = _broken(tmp_path, N, "address: 0x02, level: 0, role: NP3", "address: 0x01, level: 0, role: NP3")
    text = target.read_text().replace("role: USRC, bus: sensor,", "role: USRC, bus: sensr,")
    target.write_text(text)
    run = subprocess.run([sys.executable, "-m", "arachnae", "spec", "check", "--spec", str(tmp_path)],
                         capture_output=True, text=True)
    assert run.returncode == 1
    lines = run.stderr.strip().splitlines()
    assert len(lines) == 2 and all(line.startswith(f"{target}:") for line in lines), run.stderr
    assert "Traceback" not in run.stderr


def test_missing_spec_file_is_one_line(tmp_path: Path) -> None:
    run = subprocess.run([sys.executable, "-m", "arachnae", "spec", "check", "--spec", str(tmp_path)],
                         capture_output=True, text=True)
    assert run.returncode == 1
    assert run.stderr.strip() == f"{tmp_path / N}: cannot read: No such file or directory"


def test_a_requester_without_a_record_is_named_at_its_bus(tmp_path: Path) -> None:
    """seed 3.2.2: a slave that requests the line must have a record for its master (messages.<m>.record);
    the problem is the bus's, so nodes.yaml's request_message line is named."""
    _broken(tmp_path, M, "    record: true\n    relayed_as: DATA", "    relayed_as: DATA")
    nodes = tmp_path / N
    with pytest.raises(UserError) as err:
        load_spec(tmp_path)
    line = _line_of(nodes, "request_message: XMIT_REQ")
    for role in ("APU_SDF", "RLC", "SPU"):               # XMIT_RECORD's senders, which send no other record
        assert f"{nodes}:{line}: bus first: {role} requests the line but sends MCP no message with `record: true`" \
            in str(err.value).splitlines()
