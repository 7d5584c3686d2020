"""MCP POST (seed 6.3, 3.2.2; docs/decisions.md D2, D3): ID_REQ with one retry, sub-master reports, the verdict."""
from __future__ import annotations

import pytest

from arachnae_proto import messages as M
from arachnae_proto.enums import Direction, Gait
from arachnae_proto.network import ADDRESS_OF as A, BROADCAST

from tests.behaviours.rig import Rig

MCP = A["MCP"]


def first_bus(silent=(), reports=None):
    """Scripted first-level nodes: `silent` never answer; sub-masters report `reports[short]`."""
    reports = reports or {}
    quiet = {A[s] for s in silent}

    def respond(f):
        m, a = f.message, f.dst
        if a in quiet:
            return []
        if isinstance(m, M.IdReq):
            return [(a, M.IdAck(address=a))]
        if isinstance(m, M.StatusReq) and a == A["MMC"]:
            return [(a, M.StatusAckMmc(gait=int(Gait.TRIPOD), direction=int(Direction.STOP), leg=0, error=0))]
        if isinstance(m, M.PostQuery):
            short = {A["MMC"]: "MMC", A["SPU"]: "SPU"}[a]
            return [(a, M.PostReport(missing=[A[s] for s in reports.get(short, ())]))]
        return []
    return respond


def post(spec, **kw) -> Rig:
    rig = Rig(spec, "MCP", MCP, first_bus(**kw))
    rig.run(1.0)
    return rig


def test_all_present_is_operational_and_starts_the_np3(spec):
    rig = post(spec)
    assert rig.node.verdict.verdict == "OPERATIONAL"
    assert [f.dst for _, f in rig.frames(M.Init)] == [BROADCAST]       # seed 3.2.3: INIT via broadcasting starts navigation
    assert {f.dst for _, f in rig.frames(M.IdReq)} == {A[s] for s in ("NP3", "MMC", "SPU", "SSC", "APU/SDF", "UIC/RCP", "RLC")}


def test_missing_optional_node_is_degraded_after_one_retry(spec):
    rig = post(spec, silent=("SSC",))
    v = rig.node.verdict
    assert (v.verdict, v.missing, v.reasons) == ("DEGRADED", ("SSC",), ("SSC missing (optional)",))
    assert len(rig.frames(M.IdReq, A["SSC"])) == 2                      # seed 3.2.2: one retry, then missing
    assert rig.frames(M.Init)                                          # the robot still runs


def test_missing_required_sensor_behind_the_spu_halts(spec):
    rig = post(spec, reports={"SPU": ("USRC",)})
    v = rig.node.verdict
    assert v.verdict == "HALTED" and "USRC missing (required)" in v.reasons
    assert rig.frames(M.Init) == []                                    # seed 3.2.2: a missing required node stops it


def test_silent_sub_master_takes_its_bus_with_it(spec):
    rig = post(spec, silent=("SPU",))
    v = rig.node.verdict
    assert v.verdict == "HALTED"
    assert set(v.missing) == {"SPU", "USRC", "TPSC", "IRRC", "ISC", "TSC", "LSC", "PSC"}   # docs/decisions.md D2
    assert rig.frames(M.PostQuery, A["SPU"]) == []                     # no POST_QUERY to a node that is gone


@pytest.mark.parametrize("lost, verdict, reason", [
    (("JAC(2,3)",), "DEGRADED", "legs: 2 incomplete"),                # seed 6.3: one leg may be missing
    (("LCP(1)", "JAC(1,1)", "JAC(1,2)", "JAC(1,3)", "JAC(4,1)"), "HALTED", "legs: 4 of 6 complete, at least 5 needed"),
])
def test_leg_quorum(spec, lost, verdict, reason):
    rig = post(spec, reports={"MMC": lost})
    v = rig.node.verdict
    assert v.verdict == verdict and reason in v.reasons


def test_move_is_relayed_and_resent_until_the_mmc_status_confirms_it(spec):
    """spec protocol.move_retries: MOVE_RELAYED has no reply; the MCP checks STATUS_ACK_MMC and resends."""
    rig = Rig(spec, "MCP", MCP, first_bus())                           # the scripted MMC always says STOP
    rig.run(1.0)

    def np3_move(f):
        if isinstance(f.message, M.XmitGrant):
            return [(f.dst, M.Move(mov_cmd=int(Direction.FORWARD), param=0))]
        return first_bus()(f)
    rig.respond = np3_move
    rig.inject(1.1, A["NP3"], M.XmitReq())
    rig.run(2.0)
    relayed = rig.frames(M.MoveRelayed)
    assert len(relayed) == 1 + spec.protocol.move_retries
    assert all(f.message.address == A["NP3"] and f.message.mov_cmd == Direction.FORWARD for _, f in relayed)


def test_post_finishes_while_other_traffic_keeps_the_bus_busy(spec):
    """seed 6.3: POST at any time. A master whose bus never falls idle (the MMC's gait traffic while walking)
    still queries its sub-masters once its own ID_REQs and STATUS_REQs are done (post_rerun seed 2 ended
    HALTED: the MMC's report waited for an idle leg bus for 5 s)."""
    rig = Rig(spec, "MCP", MCP, first_bus())
    node, link = rig.node, rig.node.links[rig.node.master_bus]

    def chatter() -> None:                       # always one more transaction waiting behind the current one
        if not link.queue:
            node.request(A["MMC"], M.StatusReq(), (M.StatusAckMmc,))
    node.every(0.002, chatter)
    rig.run(1.0)
    assert rig.node.verdict.verdict == "OPERATIONAL"
    assert {f.dst for _, f in rig.frames(M.PostQuery)} == {A["MMC"], A["SPU"]}
    queried = max(t for t, _ in rig.frames(M.PostQuery))
    assert any(t > queried for t, _ in rig.frames(M.StatusReq, A["MMC"]))   # the bus stayed busy throughout
