"""Issue 10, item 7: `arachnae decode` refuses frames and --own values that break the spec's addressing."""
from __future__ import annotations

import pytest
from arachnae_proto import frame
from arachnae_proto import messages as M
from arachnae_proto.network import ADDRESS_OF, BROADCAST

from tests.hostile.conftest import assert_one_line_error

MOVE = M.Move(mov_cmd=1, param=0)
MCP, NP3, UIC = ADDRESS_OF["MCP"], ADDRESS_OF["NP3"], ADDRESS_OF["UIC/RCP"]     # MOVE: NP3 -> MCP

# (name, frame bytes, extra arguments, fragment of the one-line error)
CASES = [
    ("source not a node", frame.build(MCP, 0x99, MOVE), [], "source 0x99 is not a node address"),
    ("source is broadcast", frame.build(MCP, BROADCAST, MOVE), [], "source 0xFF is not a node address"),
    ("source zero", frame.build(MCP, 0x00, MOVE), [], "source 0x00 is not a node address"),
    ("destination not a node", frame.build(0x99, NP3, MOVE), [], "destination 0x99 is not a node address"),
    ("broadcast MOVE", frame.build(BROADCAST, NP3, MOVE), [], "the spec does not mark MOVE broadcast"),
    ("broadcast with --own", frame.build(BROADCAST, NP3, MOVE), ["--own", "MCP"], "does not mark MOVE broadcast"),
    ("sender role", frame.build(MCP, ADDRESS_OF["PSC"], MOVE), [], "MOVE from PSC, but only"),
    ("receiver role", frame.build(UIC, NP3, MOVE), [], "MOVE to UIC/RCP, but only"),
    ("--own not a number", frame.build(MCP, NP3, MOVE), ["--own", "xyz"], "--own 'xyz': expected a node address"),
    ("--own broadcast", frame.build(MCP, NP3, MOVE), ["--own", "0xFF"], "--own 0xFF: not a node address"),
    ("--own unused address", frame.build(MCP, NP3, MOVE), ["--own", "0x99"], "--own 0x99: not a node address"),
    ("--own negative", frame.build(MCP, NP3, MOVE), ["--own", "-1"], "--own -1: not a node address"),
    ("--own huge", frame.build(MCP, NP3, MOVE), ["--own", "9" * 5000], "expected a node address"),
    ("--own other node", frame.build(MCP, NP3, MOVE), ["--own", "SPU"], "ADDRESS: frame for 0x01, not for 0x04"),
]


@pytest.mark.parametrize("name, data, extra, fragment", CASES, ids=[c[0] for c in CASES])
def test_decode_refuses_bad_addresses_in_one_line(cli, name, data, extra, fragment):
    assert_one_line_error(cli("decode", data.hex(), *extra), "decode: ", fragment)


@pytest.mark.parametrize("dst, src, own", [(MCP, NP3, None), (MCP, NP3, "0x01"), (MCP, UIC, "1"),
                                           (MCP, NP3, "MCP"), (BROADCAST, MCP, "MMC")])
def test_decode_accepts_what_the_spec_allows(cli, dst, src, own):
    msg = MOVE if dst != BROADCAST else M.Init()
    run = cli("decode", frame.build(dst, src, msg).hex(), *(["--own", own] if own else []))
    assert run.code == 0, run.err


def test_every_frame_of_a_run_passes_the_address_and_route_checks(tmp_path, spec):
    """No false alarm: what the simulated robot really sends (a 3 s run) passes the codec's address and route
    checks and the role check `decode` adds."""
    from sim2d.scenario import load_scenario
    from sim2d.sim import Simulation

    path = tmp_path / "s.yaml"
    path.write_text("duration: 3\narena: {size: [3, 3]}\nrobot: {pose: [1.5, 1.5, 0]}\n")
    result = Simulation(load_scenario(path, spec), spec).run()
    checked = 0
    for entry in result.frames:
        frame.check_roles(frame.parse(entry.sent))
        checked += 1
    assert checked > 300
