"""Work a run does once that it used to do several times (issue 17's long sweeps): the same answers, once."""
from __future__ import annotations

from arachnae_proto.frame import build, check
from arachnae_proto.messages import BY_NAME as MESSAGES
from arachnae_proto.network import ADDRESS_OF

from behaviours.runtime import line_check
from sim2d import runner
from tracecheck.trace import COLUMNS, frame_row, trace_lines

SHORT = """name: short
duration: 3
arena: {size: [4, 3]}
robot: {pose: [2, 1.5, 0], task: idle, absent: [PSC]}
expect: {post: DEGRADED}
"""


def _frame(src: str = "MCP", dst: str = "MMC") -> bytes:
    return build(ADDRESS_OF[dst], ADDRESS_OF[src], MESSAGES["ID_REQ"]())


def test_line_check_answers_for_the_bytes_it_is_given_not_the_last_ones():
    good = _frame()
    bad = good[:-1] + bytes([good[-1] ^ 0x01])            # checksum broken
    other = _frame("MMC", "MCP")
    assert line_check(good) == check(good)
    assert line_check(bad) is None
    assert line_check(other) == check(other) != check(good)
    assert line_check(bytes(bytearray(good))) == check(good)   # equal bytes, another object


def test_a_frame_reads_the_same_the_second_time_and_a_corrupt_one_shows_the_codec_reason():
    good = _frame()
    bad = good[:-1] + bytes([good[-1] ^ 0x01])
    first = frame_row(0.0, 0.001, "first_level", "MCP", good, good, ())
    assert frame_row(0.0, 0.001, "first_level", "MCP", good, good, ()) == first
    assert "\tID_REQ" in first and f"\t{good.hex()}\t" in first
    corrupt = frame_row(0.0, 0.001, "first_level", "MCP", good, bad, ("corrupt",))
    assert "<CHECKSUM:" in corrupt and corrupt.endswith(f"\tcorrupt\t{good.hex()}")


def test_the_trace_written_is_the_trace_the_protocol_metrics_read(tmp_path):
    """Both read Result.trace_rows, made once from the frames and notes (decoding them took ~15 % of a run)."""
    p = tmp_path / "short.yaml"
    p.write_text(SHORT)
    outcome = runner.run(str(p))                      # the spec: runner.load_spec_once
    r = outcome.result
    assert r.trace_rows == trace_lines(r.frames, r.notes)
    assert any("\tdebug\t" in row for row in r.trace_rows) and len(r.trace_rows) > len(r.notes)
    out = runner.write_outputs(outcome, tmp_path / "run")
    assert (out / "trace.tsv").read_text() == "\t".join(COLUMNS) + "\n" + "\n".join(r.trace_rows) + "\n"
    assert r.metrics["protocol"]["violations"] == 0


def test_the_spec_is_loaded_once_per_process():
    assert runner.load_spec_once() is runner.load_spec_once()
