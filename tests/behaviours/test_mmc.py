"""MMC (seed 3.2.4): MOVE becomes alternating tripod LEG_TARGETs; STATUS_ACK tells gait and direction."""
from __future__ import annotations

from arachnae_proto import messages as M
from arachnae_proto.enums import Direction, Gait, LegFlags, LegPhase, MmcError, MovCmd
from arachnae_proto.network import ADDRESS_OF

from behaviours.geometry import DEFAULT_GEOMETRY as G
from tests.behaviours.rig import Rig

MCP, MMC, NP3 = ADDRESS_OF["MCP"], ADDRESS_OF["MMC"], ADDRESS_OF["NP3"]
LCP = {leg: 0x20 + leg for leg in range(1, 7)}          # seed 3.2.1
LEG_OF = {a: leg for leg, a in LCP.items()}


def legs_answer(report_flags: int = int(LegFlags.CONTACT)):
    def respond(f):
        m = f.message
        if isinstance(m, M.IdReq):
            return [(f.dst, M.IdAck(address=f.dst))]
        if isinstance(m, M.StatusReq):
            return [(f.dst, M.StatusAckOrder(status=0))]
        if isinstance(m, M.PostQuery):
            return [(f.dst, M.PostReport(missing=[]))]
        if isinstance(m, M.LegPoll):
            return [(f.dst, M.LegReport(flags=report_flags, x=0, y=0, z=0, servo_temp=20))]
        return []
    return respond


def walking_rig(spec, seconds: float, flags: int = int(LegFlags.CONTACT)) -> Rig:
    rig = Rig(spec, "MMC", MMC, legs_answer(flags))
    rig.inject(0.5, MCP, M.MoveRelayed(address=NP3, mov_cmd=int(MovCmd.TRIPOD), param=0))
    rig.inject(0.55, MCP, M.MoveRelayed(address=NP3, mov_cmd=int(MovCmd.FORWARD), param=0))
    rig.run(0.55 + seconds)
    return rig


def test_forward_becomes_alternating_tripod_leg_targets(spec):
    rig = walking_rig(spec, 8 * G.half_cycle)
    # the new segments (not the refreshes of one) after the first half cycle, in order
    seen: dict[int, tuple] = {}
    starts: list[tuple[float, int, M.LegTarget]] = []
    for t, f in rig.frames(M.LegTarget):
        m = f.message
        key = (m.phase, m.x, m.y, m.z)
        if seen.get(f.dst) != key:
            seen[f.dst] = key
            if t > 0.55 + G.half_cycle:
                starts.append((t, LEG_OF[f.dst], m))
    swings = [(t, leg) for t, leg, m in starts if m.phase == LegPhase.SWING]
    stances = [(t, leg) for t, leg, m in starts if m.phase == LegPhase.STANCE]
    assert len(swings) >= 18 and len(stances) >= 18
    # group the swing starts by half cycle: each group is one tripod, the tripods alternate
    groups: list[set[int]] = []
    last_t = -1.0
    for t, leg in swings:
        if t - last_t > G.half_cycle / 2:
            groups.append(set())
        groups[-1].add(leg)
        last_t = t
    full = groups[1:-1]                                   # the first and last may be cut off by the window
    assert all(g in ({1, 3, 5}, {2, 4, 6}) for g in full), groups
    assert all(a != b for a, b in zip(full, full[1:])), groups
    # while one tripod swings the other is in stance
    for t, leg in swings:
        other = [lg for ts, lg in stances if abs(ts - t) < G.half_cycle / 4]
        assert set(other) & {leg} == set()
    # targets: swing ends half a stroke ahead of the hip, lifted; stance ends half a stroke behind
    stroke_raw = round(G.stroke / 2 * 10000)                     # LEG_TARGET x in 0.1 mm
    reach_raw = round(G.neutral_reach * 10000)
    for t, leg, m in starts:
        side = 1 if leg <= 3 else -1
        assert m.y == side * reach_raw
        if m.phase == LegPhase.SWING:
            assert (m.x, m.z) == (stroke_raw, round(G.lift * 10000))
            assert abs(m.duration - G.half_cycle * 1000) <= 25      # ms, within one MMC period
        else:
            assert (m.x, m.z) == (-stroke_raw, 0)


def test_unchanged_targets_are_refreshed_at_the_spec_period(spec):
    rig = Rig(spec, "MMC", MMC, legs_answer())
    rig.run(3.0)                                                  # standing: every leg holds
    refresh = spec.protocol.setpoint_refresh_ms / 1000
    times = [t for t, f in rig.frames(M.LegTarget, LCP[4])]
    assert len(times) >= 10 and all(f.message.phase == LegPhase.HOLD for _, f in rig.frames(M.LegTarget, LCP[4]))
    gaps = [b - a for a, b in zip(times, times[1:])]
    assert all(refresh - 0.001 <= g <= refresh + 0.03 for g in gaps), gaps


def test_status_ack_reports_gait_direction_and_a_blocked_leg(spec):
    rig = walking_rig(spec, 1.0, flags=int(LegFlags.CONTACT | LegFlags.BLOCKED))
    rig.inject(rig.board.t + 0.01, MCP, M.StatusReq())
    rig.run(rig.board.t + 0.1)
    (_, f), = rig.frames(M.StatusAckMmc)
    ack = f.message
    assert (ack.gait, ack.direction) == (Gait.TRIPOD, Direction.FORWARD)
    assert ack.error == MmcError.LEG_DRIVE_BLOCKED and 1 <= ack.leg <= 6     # seed 6.1


def test_no_ground_under_a_foot_stops_the_robot(spec):
    rig = walking_rig(spec, 1.0, flags=int(LegFlags.NO_GROUND))
    assert rig.node.gait.command == MovCmd.STOP                  # seed 1.2.2: a pit
    assert any(e == "pit" for _, e, _ in rig.board.notes)


def test_post_reports_a_missing_leg_and_walks_on_five_in_wave_gait(spec):
    def respond(f):
        if f.dst == LCP[2]:
            return []                                             # LCP(2) never answers
        return legs_answer()(f)
    rig = Rig(spec, "MMC", MMC, respond)
    rig.inject(0.5, MCP, M.PostQuery())
    rig.inject(0.6, MCP, M.MoveRelayed(address=NP3, mov_cmd=int(MovCmd.FORWARD), param=0))
    rig.run(3.0)
    (_, f), = rig.frames(M.PostReport)
    jacs_2 = {0x44, 0x45, 0x46}                                   # JAC(2,m) = 0x41 + 3 + (m-1), seed 3.2.18
    assert set(f.message.missing) == {LCP[2]} | jacs_2            # decision 2: nodes behind it are missing too
    assert len(rig.frames(M.IdReq, LCP[2])) == 2                  # seed 3.2.2: one retry
    assert rig.node.gait.gait == Gait.WAVE
    assert rig.frames(M.LegTarget, LCP[1]) and not rig.frames(M.LegTarget, LCP[2])
