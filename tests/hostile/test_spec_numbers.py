"""Numbers are numbers (issue 10, item 3): NaN, infinity, floats and booleans where integers are meant,
malformed, zero or negative fractions are refused at their line by `spec check`, `codegen` and `timing`,
never a traceback and never `nan ms`."""
from __future__ import annotations

from pathlib import Path

import pytest

from tests.hostile.spec_harness import M, N, refused_everywhere, replace, spec_copy

PSC_SCALE = '{name: voltage, type: uint, bits: 8, unit: V, scale: "1/200"'
ADDRESS = "address: 0x02, level: 0"
OPCODE = "{name: OBJ_BOTH, opcode: 0x50"
TURNAROUND = "turnaround_us: 500"
RANGE = "{name: line, type: uint, bits: 8, range: [0, 1]}"
FRACTION = "a finite number or a fraction 'a/b' of integers with b > 0"     # the schema's description of a number

CASES = [
    ("address_float", N, ADDRESS, "address: 2.0, level: 0", "nodes[1].address: expected an integer, got 2.0"),
    ("address_bool", N, ADDRESS, "address: true, level: 0", "nodes[1].address: expected an integer, got True"),
    ("address_nan", N, ADDRESS, "address: .nan, level: 0", "'.nan' is not a finite number"),
    ("opcode_float", M, OPCODE, "{name: OBJ_BOTH, opcode: 1.0", "opcode: expected an integer, got 1.0"),
    ("opcode_bool", M, OPCODE, "{name: OBJ_BOTH, opcode: false", "opcode: expected an integer, got False"),
    ("turnaround_nan", N, TURNAROUND, "turnaround_us: .nan", "'.nan' is not a finite number"),
    ("turnaround_inf", N, TURNAROUND, "turnaround_us: .inf", "'.inf' is not a finite number"),
    ("turnaround_huge", N, TURNAROUND, "turnaround_us: 1.0e+308", "turnaround_us: must be <= 1000000, got 1e+308"),
    ("baud_float", N, "baud: 2400,", "baud: 2400.0,", "buses.sensor.baud: expected an integer, got 2400.0"),
    ("scale_zero_denominator", M, PSC_SCALE, PSC_SCALE.replace('"1/200"', '"1/0"'), f"scale: expected {FRACTION}, got '1/0'"),
    ("scale_float_numerator", M, PSC_SCALE, PSC_SCALE.replace('"1/200"', '"1.5/2"'), f"scale: expected {FRACTION}, got '1.5/2'"),
    ("scale_negative_fraction", M, PSC_SCALE, PSC_SCALE.replace('"1/200"', '"-10/255"'), "scale must be positive, not -10/255"),
    ("scale_zero", M, PSC_SCALE, PSC_SCALE.replace('"1/200"', "0"), "scale must be positive, not 0"),
    ("scale_nan", M, PSC_SCALE, PSC_SCALE.replace('"1/200"', ".nan"), "'.nan' is not a finite number"),
    ("scale_words", M, PSC_SCALE, PSC_SCALE.replace('"1/200"', '"one/200"'), f"scale: expected {FRACTION}, got 'one/200'"),
    ("scale_bool", M, PSC_SCALE, PSC_SCALE.replace('"1/200"', "true"), f"scale: expected {FRACTION}, got True"),
    ("scale_too_big_for_c", M, PSC_SCALE, PSC_SCALE.replace('"1/200"', "100000000"), "does not fit the C helpers' int32_t"),
    ("range_nan", M, RANGE, RANGE.replace("[0, 1]", "[0, .nan]"), "'.nan' is not a finite number"),
    ("range_inf", M, RANGE, RANGE.replace("[0, 1]", "[-.inf, 1]"), "'-.inf' is not a finite number"),
    ("bits_float", M, RANGE, RANGE.replace("bits: 8", "bits: 8.0"), "bits: expected an integer, got 8.0"),
    ("enum_value_float", M, "HOLD: 3}", "HOLD: 3.5}", "values.HOLD: expected an integer, got 3.5"),
    ("enum_value_huge", M, "HOLD: 3}", "HOLD: 1180591620717411303424}", "values.HOLD: must be <= 65535, got 1180591620717411303424"),
    ("poly_wider_than_crc", M, "poly: 0x1021", "poly: 0x11021", "checksum.poly: must be <= 65535, got 69665"),
    ("log_per_decade_huge", M, "per_decade: 64, saturate: true}, range: [0.1, 1000]}",
     "per_decade: 100000, saturate: true}, range: [0.1, 1000]}", "log10.per_decade: must be <= 255, got 100000"),
]
COMMANDS = (("spec", "check"), ("codegen",), ("timing",))


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_bad_number_is_refused_by_every_command(tmp_path: Path, case) -> None:
    _id, file, old, new, expect = case
    spec_dir = spec_copy(tmp_path)
    replace(spec_dir, file, old, new)
    refused_everywhere(tmp_path, spec_dir, file, expect, COMMANDS)
