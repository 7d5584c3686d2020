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


def status(rig: Rig) -> M.StatusAckMmc:
    rig.inject(rig.board.t + 0.01, MCP, M.StatusReq())
    rig.run(rig.board.t + 0.1)
    return rig.frames(M.StatusAckMmc)[-1][1].message


def move(rig: Rig, cmd: MovCmd) -> None:
    rig.inject(rig.board.t + 0.01, MCP, M.MoveRelayed(address=NP3, mov_cmd=int(cmd), param=0))
    rig.run(rig.board.t + 0.05)


def scripted_legs(flags: dict[int, int], silent: set[int], status: dict[int, int] | None = None):
    """Legs answering with per-leg LEG_REPORT flags (changeable during the test); `silent` legs never answer."""
    def respond(f):
        leg = LEG_OF.get(f.dst)
        if leg in silent:
            return []
        if isinstance(f.message, M.LegPoll):
            return [(f.dst, M.LegReport(flags=flags.get(leg, int(LegFlags.CONTACT)), x=0, y=0, z=0, servo_temp=20))]
        if isinstance(f.message, M.StatusReq) and leg is not None and rig_started[0]:
            return [(f.dst, M.StatusAckOrder(status=(status or {}).get(leg, 0)))]
        return legs_answer()(f)
    rig_started = [False]
    respond.started = rig_started                                 # type: ignore[attr-defined]
    return respond


def started_rig(spec, flags, silent, st=None) -> Rig:
    respond = scripted_legs(flags, silent, st)
    rig = Rig(spec, "MMC", MMC, respond)
    rig.run(0.5)
    respond.started[0] = True                                     # POST is over: run-time answers from now on
    move(rig, MovCmd.FORWARD)
    return rig


def test_no_ground_stops_the_robot_once_and_the_next_move_walks_away(spec):
    flags: dict[int, int] = {}
    rig = started_rig(spec, flags, set())
    rig.run(1.5)
    flags[2] = int(LegFlags.NO_GROUND)                            # leg 2's foot finds a pit
    rig.run(2.5)
    assert rig.node.gait.command == MovCmd.STOP                  # seed 1.2.2: stop at once (local safety)
    ack = status(rig)
    assert (ack.error, ack.leg, ack.direction) == (MmcError.NO_GROUND, 2, Direction.STOP)
    move(rig, MovCmd.BACKWARD)                                    # the NP3 backs off: obeyed although the
    rig.run(rig.board.t + 1.0)                                    # foot still finds no ground
    assert rig.node.gait.command == MovCmd.BACKWARD and status(rig).error == MmcError.NO_GROUND
    assert sum(1 for _, e, _ in rig.board.notes if e == "pit") == 1
    flags[2] = int(LegFlags.CONTACT)                              # the foot has ground again: error clears
    rig.run(rig.board.t + 1.0)
    assert status(rig).error == MmcError.NONE


def test_a_silent_lcp_is_out_of_order_and_five_legs_walk_on(spec):
    silent: set[int] = set()
    rig = started_rig(spec, {}, silent)
    rig.run(2.0)
    silent.add(3)                                                 # LCP(3) dies
    rig.run(2.6)
    ack = status(rig)
    assert (ack.error, ack.leg) == (MmcError.LCP_OUT_OF_ORDER, 3) and ack.direction == Direction.FORWARD
    assert [d for _, e, d in rig.board.notes if e == "five_legged_gait"] == [{"leg": 3}]
    assert rig.node.gait.legs == (1, 2, 4, 5, 6) and ack.gait == Gait.WAVE
    t = rig.board.t
    rig.run(t + 6.0)
    late = [f.dst for ts, f in rig.frames(M.LegTarget) if ts > t]
    assert LCP[3] not in late and {LCP[1], LCP[6]} <= set(late)
    swings = {LEG_OF[f.dst] for ts, f in rig.frames(M.LegTarget) if ts > t + 1 and f.message.phase == LegPhase.SWING}
    assert swings == {1, 2, 4, 5, 6}                              # all five others step
    assert rig.node.gait.max_up == 1                              # one foot up, four down


def test_a_jac_fault_loses_the_leg_and_holds_it_lifted(spec):
    flags: dict[int, int] = {}
    rig = started_rig(spec, flags, set())
    rig.run(2.0)
    flags[5] = int(LegFlags.JAC_FAULT)
    rig.run(3.0)
    ack = status(rig)
    assert (ack.error, ack.leg) == (MmcError.JAC_OUT_OF_ORDER, 5)
    (_, last), *_ = reversed(rig.frames(M.LegTarget, LCP[5]))
    assert last.message.phase == LegPhase.RETRACT and last.message.phys()["z"] > 0      # out of the way


def test_blocked_leg_then_failed_then_clean(spec):
    flags: dict[int, int] = {}
    st: dict[int, int] = {}
    rig = started_rig(spec, flags, set(), st)
    rig.run(1.5)
    flags[4] = int(LegFlags.CONTACT | LegFlags.BLOCKED)
    rig.run(2.5)
    assert (status(rig).error, status(rig).leg) == (MmcError.LEG_DRIVE_BLOCKED, 4)
    swing_lifts = [f.message.z for ts, f in rig.frames(M.LegTarget) if ts > 2.0 and f.message.phase == LegPhase.SWING]
    assert swing_lifts and min(swing_lifts) > round(G.lift * 10000)     # every leg steps high near the obstacle
    st[4] = 1                                                     # the LCP's retry was blocked too
    rig.run(3.5)
    assert status(rig).error == MmcError.LEG_DRIVE_FAILED
    flags[4] = int(LegFlags.CONTACT)                              # a clean step
    st[4] = 0
    rig.run(4.5)
    assert status(rig).error == MmcError.NONE


def test_overtemperature_slows_the_gait(spec):
    flags: dict[int, int] = {}
    rig = started_rig(spec, flags, set())
    rig.run(1.5)
    assert rig.node.gait.scale == 1.0
    flags[6] = int(LegFlags.CONTACT | LegFlags.OVERTEMP)
    rig.run(2.5)
    assert rig.node.gait.scale < 1.0
    flags[6] = int(LegFlags.CONTACT)
    rig.run(3.5)
    assert rig.node.gait.scale == 1.0


def test_gait_change_while_walking_keeps_the_direction(spec):
    rig = walking_rig(spec, 3.0)
    move(rig, MovCmd.RIPPLE)
    ack = status(rig)
    assert (ack.gait, ack.direction) == (Gait.RIPPLE, Direction.FORWARD)     # seed 3.2.3
    rig.run(rig.board.t + 4.0)
    assert rig.node.gait.running == MovCmd.RIPPLE and rig.node.gait.command == MovCmd.FORWARD
    assert rig.node.debug_metrics()["gait_switches"] == 1


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
    assert set(f.message.missing) == {LCP[2]} | jacs_2            # docs/decisions.md D2: nodes behind it are missing too
    assert len(rig.frames(M.IdReq, LCP[2])) == 2                  # seed 3.2.2: one retry
    assert rig.node.gait.gait == Gait.WAVE
    assert rig.frames(M.LegTarget, LCP[1]) and not rig.frames(M.LegTarget, LCP[2])
