"""`arachnae trace check` on a saved trace: clean runs pass, a tampered trace names the offending frame,
a bad trace file is a one-line file:line error."""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from sim2d import runner


def cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "arachnae", *args], capture_output=True, text=True, timeout=300)


@pytest.fixture(scope="module")
def saved(missing_scenario, tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("run") / "o"
    runner.write_outputs(runner.run(str(missing_scenario)), out)
    return out


def rows(path: Path) -> list[list[str]]:
    return [line.split("\t") for line in path.read_text().splitlines()]


def write(path: Path, table: list[list[str]]) -> Path:
    path.write_text("\n".join("\t".join(r) for r in table) + "\n")
    return path


def test_saved_run_checks_clean_and_reports_protocol_metrics(saved):
    m = json.loads((saved / "metrics.json").read_text())
    assert m["protocol"]["violations"] == 0 and m["protocol"]["k_slots"]["sensor"] > 0
    assert {"name": "protocol.violations eq", "passed": True, "detail": "protocol.violations = 0, eq 0"} \
        in m["expectations"]
    p = cli("trace", "check", str(saved / "trace.tsv"))
    assert p.returncode == 0, p.stdout + p.stderr
    assert "0 protocol violation(s)" in p.stdout


def test_overlapping_frames_are_two_talkers(saved, tmp_path):
    table = rows(saved / "trace.tsv")
    i = next(i for i, r in enumerate(table[1:], 1) if r[2] == "leg" and r[3] == "LCP(2)")
    prev = next(r for r in reversed(table[1:i]) if r[2] == "leg")
    table[i][0] = f"{float(prev[1]) - 0.001:.6f}"          # LCP(2)'s reply starts before the MMC's frame ended
    p = cli("trace", "check", str(write(tmp_path / "t.tsv", table)))
    assert p.returncode == 1
    lines = p.stdout.splitlines()
    assert lines[0].startswith(f"{float(prev[1]) - 0.001:.6f} s bus leg (trace line {i + 1}): one_talker: two talkers")
    assert "1 protocol violation(s)" in lines[-1]


def test_a_missing_retry_is_named(saved, tmp_path):
    table = rows(saved / "trace.tsv")
    reqs = [i for i, r in enumerate(table) if r[2] == "sensor" and r[6] == "ID_REQ" and r[5] == "PSC"]
    assert len(reqs) == 2                                  # seed 3.2.2: one retry to the absent PSC
    del table[reqs[1]]
    p = cli("trace", "check", str(write(tmp_path / "t.tsv", table)), "--json")
    out = json.loads(p.stdout)
    assert p.returncode == 1 and out["by_rule"] == {"id_retry": 1} or "id_retry" in out["by_rule"]
    assert "bus sensor" in out["first"] and "no reply to ID_REQ 1 of 2 to PSC" in out["first"]


def test_bad_trace_files_are_one_line_errors(saved, tmp_path):
    bad = tmp_path / "bad.tsv"
    bad.write_text("time\tbus\n")
    p = cli("trace", "check", str(bad))
    assert p.returncode == 1 and p.stderr == f"{bad}:1: not a bus trace: header must start with " \
        "start_s end_s bus sender src dst message bytes flags\n"
    table = rows(saved / "trace.tsv")
    table[5][7] = "zz"
    p = cli("trace", "check", str(write(tmp_path / "hex.tsv", table)))
    assert p.returncode == 1 and p.stderr == f"{tmp_path / 'hex.tsv'}:6: bytes column is not hexadecimal\n"
    table = rows(saved / "trace.tsv")
    table[3][2] = "nobus"
    p = cli("trace", "check", str(write(tmp_path / "bus.tsv", table)))
    assert p.returncode == 1 and p.stderr.startswith(f"{tmp_path / 'bus.tsv'}:4: unknown bus 'nobus'")
    p = cli("trace", "check", str(tmp_path / "none.tsv"))
    assert p.returncode == 1 and p.stderr.count("\n") == 1 and "cannot read trace" in p.stderr
    p = cli("trace", "check", str(saved / "trace.tsv"), "--arbitration", "sensor=maybe")
    assert p.returncode == 1 and p.stderr.startswith("--arbitration: expected BUS=seed|spec")


def test_new_fault_kinds_are_checked(tmp_path):
    from arachnae.errors import UserError
    from sim2d.scenario import load_scenario

    base = "duration: 3\narena: {size: [4, 3]}\nrobot: {pose: [1, 1, 0]}\n"
    for fault, msg in (("{at: 1, request: TPSC, until: 2}", "no until"),
                       ("{at: 1, collide: [TPSC, MMC]}", "is not one of"),
                       ("{at: 1, collide: [TPSC, SPU]}", "share one bus"),
                       ("{at: 1, request: MMC}", "is not one of")):
        p = tmp_path / "s.yaml"
        p.write_text(base + f"faults:\n  - {fault}\n")
        with pytest.raises(UserError, match=msg) as err:
            load_scenario(p, runner.load_spec_once())
        assert str(err.value).startswith(f"{p}:5: ")
    p.write_text(base + "arbitration: {leg: seed}\n")
    with pytest.raises(UserError, match="unknown key 'leg'"):
        load_scenario(p, runner.load_spec_once())


def test_a_runs_pcapng_checks_like_its_trace(saved, tmp_path):
    """A capture (here the run's own bus.pcapng, exact clock) is validated like trace.tsv: same verdict, same
    figures; a pcapng of a bus the spec does not have is a one-line error naming the file."""
    from captures.pcapng import read_file, write_file

    p = cli("trace", "check", str(saved / "bus.pcapng"), "--json")
    t = cli("trace", "check", str(saved / "trace.tsv"), "--json")
    assert p.returncode == t.returncode == 0, p.stdout + p.stderr
    cap, tsv = json.loads(p.stdout), json.loads(t.stdout)
    assert {k: cap[k] for k in ("violations", "requests", "served", "max_wait_slots")} == \
        {k: tsv[k] for k in ("violations", "requests", "served", "max_wait_slots")}
    assert cap["checked"]["id_req"] == tsv["checked"]["id_req"] > 0
    capture = read_file(saved / "bus.pcapng")
    frames = [f._replace(bus="nobus") if f.bus == "leg" else f for f in capture.frames]
    interfaces = tuple(i._replace(name="nobus") if i.name == "leg" else i for i in capture.interfaces)
    write_file(tmp_path / "bad.pcapng", interfaces, frames)
    p = cli("trace", "check", str(tmp_path / "bad.pcapng"))
    assert p.returncode == 1 and p.stderr.count("\n") == 1
    assert p.stderr.startswith(f"{tmp_path / 'bad.pcapng'}: frame ") and "'nobus' is not a bus of the spec" in p.stderr


def test_untimed_check_still_names_a_missing_retry(saved, tmp_path):
    """--untimed (a capture without a true clock) keeps the rules that need none: a dropped ID_REQ retry."""
    table = rows(saved / "trace.tsv")
    reqs = [i for i, r in enumerate(table) if r[2] == "sensor" and r[6] == "ID_REQ" and r[5] == "PSC"]
    del table[reqs[1]]
    p = cli("trace", "check", str(write(tmp_path / "t.tsv", table)), "--untimed", "--json")
    out = json.loads(p.stdout)
    assert p.returncode == 1 and "id_retry" in out["by_rule"] and "bound_K" not in out["by_rule"]
    assert "no reply to ID_REQ 1 of 2 to PSC" in out["first"]
    assert "request_slot" not in out["checked"] and "one_talker" not in out["checked"]


@pytest.mark.parametrize("corrupt", [True, False])
def test_a_move_relayed_resent_after_a_corrupt_echo_is_no_violation(saved, tmp_path, corrupt):
    """seed 3.2.2: the MCP resends a frame whose echo came back corrupt (a collision); only a resend of a frame
    that went out intact needs a STATUS_ACK_MMC showing the command not applied (protocol.move_retries)."""
    table = rows(saved / "trace.tsv")

    # (the second send may overlap a later frame: that is another rule's business, this test reads move_retries)
    i = next(i for i, r in enumerate(table[1:], 1) if r[2] == "first" and r[6].startswith("MOVE_RELAYED"))
    start, end = float(table[i][0]), float(table[i][1])
    again = list(table[i])
    again[0], again[1] = f"{end + 0.001:.6f}", f"{2 * end - start + 0.001:.6f}"
    if corrupt:                                # the first send was heard corrupt, as in a collision
        heard = bytearray(bytes.fromhex(table[i][7]))
        heard[-1] ^= 0x01
        table[i][6], table[i][7] = "<CHECKSUM: corrupted>", heard.hex()
    table.insert(i + 1, again)
    p = cli("trace", "check", str(write(tmp_path / "t.tsv", table)), "--json")
    out = json.loads(p.stdout)
    assert ("move_retries" in out["by_rule"]) is not corrupt, out


@pytest.mark.parametrize("new_record", [True, False])
def test_a_reflex_relayed_again_after_a_new_record_is_no_resend(saved, tmp_path, new_record):
    """Two whisker records in a row (seed 5.2) each make the MCP relay STOP to the MMC: the second MOVE_RELAYED
    follows a new record from the reflex source, so it is a new command, not a resend (a run of
    fault_us_killed_explore, seed 47, was flagged). Without the record between them it is a resend."""
    from arachnae_proto import frame
    from arachnae_proto import messages as M
    from arachnae_proto.enums import MovCmd, RecordKind
    from arachnae_proto.network import ADDRESS_OF

    table = rows(saved / "trace.tsv")
    i = next(i for i, r in enumerate(table[1:], 1) if r[2] == "first" and r[6].startswith("MOVE_RELAYED"))
    start, end = float(table[i][0]), float(table[i][1])
    mcp, mmc, spu, np3, tpsc = (ADDRESS_OF[n] for n in ("MCP", "MMC", "SPU", "NP3", "TPSC"))

    def row(t0: float, t1: float, src: str, dst: str, data: bytes, text: str) -> list[str]:
        r = list(table[i])
        r[0], r[1], r[3], r[4], r[5], r[6] = f"{t0:.6f}", f"{t1:.6f}", src, src, dst, text
        r[7] = r[-1] = data.hex()
        return r

    stop = frame.build(mmc, mcp, M.MoveRelayed(address=tpsc, mov_cmd=int(MovCmd.STOP), param=0))
    record = frame.build(mcp, spu, M.XmitRecord(target=np3, source=tpsc, kind=int(RecordKind.VALUE), channel=0, value=64, age=0))
    added = [row(end + 0.001, end + 0.009, "MCP", "MMC", stop, "MOVE_RELAYED")]
    if new_record:
        added.append(row(end + 0.010, end + 0.022, "SPU", "MCP", record, "XMIT_RECORD"))
    added.append(row(end + 0.023, end + 0.031, "MCP", "MMC", stop, "MOVE_RELAYED"))
    table[i + 1:i + 1] = added
    out = check_table(table)
    assert ("move_retries" in out) is not new_record, out.get("move_retries")


def test_a_request_raised_during_post_is_counted_from_its_init(tmp_path):
    """A key typed on the RCP during the POST (seed 6.3) waits for the INIT that ends it: the masters serve no
    request while they identify their nodes, and the K bound is the model of the running network. Counted
    from the first XMIT_REQ, the wait was 68 slots against K = 36 (found by tests/console through a pty)."""
    p = tmp_path / "key_in_post.yaml"
    p.write_text(f"include: {Path(__file__).resolve().parents[2] / 'scenarios' / 'common' / 'arena.yaml'}\nname: key_in_post\nduration: 4\n"
                 "robot: {pose: [1.0, 2.0, 0], task: idle}\noperator: [{at: 0.65, keys: F}]\n")
    m = runner.run(str(p)).result.metrics
    assert m["post"]["time_s"] > 0.65                          # the key came during the POST
    assert m["protocol"]["violations"] == 0, m["protocol"]["first"]
    assert m["protocol"]["served"] > 0 and m["nodes"]["UIC/RCP"]


def check_table(table: list[list[str]]) -> dict[str, list[str]]:
    """The violations' texts by rule."""
    from model_check.spec_adapter import load
    from tracecheck.trace import parse_lines
    from tracecheck.validate import validate
    out: dict[str, list[str]] = {}
    for v in validate(parse_lines(["\t".join(r) for r in table], "t.tsv"), load()).violations:
        out.setdefault(v.rule, []).append(v.text)
    return out


def test_what_the_models_leave_out_is_caught_on_the_trace(saved):
    """Issue 11 section 4: the broadcast INIT after POST (post model docstring) and record forwarding through the
    MCP (arbitration model docstring) are abstracted in the models; the validator's init_after_post and
    record_relayed rules catch a trace that breaks them."""
    table = rows(saved / "trace.tsv")
    assert check_table(table) == {}
    init = next(i for i, r in enumerate(table) if r[2] == "first" and r[6] == "INIT" and r[5] == "ALL")
    twice = table[:init + 1] + [table[init][:]] + table[init + 1:]
    gap = float(table[init][1]) - float(table[init][0]) + 0.05
    twice[init + 1][0], twice[init + 1][1] = (f"{float(table[init][k]) + gap:.6f}" for k in (0, 1))
    m = check_table(twice)
    assert len(m["init_after_post"]) == 1 and "INIT broadcast 2 time(s)" in m["init_after_post"][0], m
    # the MCP drops the first record it fetches (no DATA to its target); a later frame gives it the rule's 2 s
    rec = next(i for i, r in enumerate(table) if r[2] == "first" and r[6].startswith("XMIT_RECORD"))
    want = table[rec][6].split("source=")[1].split()[0:3]
    relay = next(i for i, r in enumerate(table[rec:], rec) if r[3] == "MCP" and r[6].startswith("DATA")
                 and r[6].split()[1:4] == [f"address={want[0]}", want[1], want[2]])
    late = table[-1][:]
    late[0], late[1] = (f"{float(late[k]) + 3:.6f}" for k in (0, 1))
    m = check_table(table[:relay] + table[relay + 1:] + [late])
    assert list(m) == ["record_relayed"] and "never relayed by the MCP" in m["record_relayed"][0], m
