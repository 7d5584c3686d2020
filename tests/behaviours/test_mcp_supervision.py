"""MCP supervision (seed 3.2.2, 3.2.17, 6.1-6.3): MMC status to the NP3, operator and supervisor messages,
battery alarm, POST again at run time."""
from __future__ import annotations

from arachnae_proto import messages as M
from arachnae_proto.enums import Alert, Direction, Gait, MmcError, RangeStatus, RecordKind, SscMessage, TpscContact
from arachnae_proto.network import ADDRESS_OF as A, BROADCAST

from behaviours import tuning as T
from tests.behaviours.rig import Rig

MCP, NP3, MMC, SPU, SSC, UIC = A["MCP"], A["NP3"], A["MMC"], A["SPU"], A["SSC"], A["UIC/RCP"]
FIRST = ("NP3", "MMC", "SPU", "SSC", "APU/SDF", "UIC/RCP", "RLC")


class FirstBus:
    """Scripted first-level nodes: an MMC with a settable error, slaves whose records are queued."""

    def __init__(self, silent=(), reports=None) -> None:
        self.silent = {A[s] for s in silent}
        self.reports = reports or {}
        self.mmc = {"error": 0, "leg": 0, "direction": int(Direction.FORWARD)}
        self.records: dict[int, list[M.Message]] = {}

    def __call__(self, f):
        m, a = f.message, f.dst
        if a in self.silent:
            return []
        if isinstance(m, M.IdReq):
            return [(a, M.IdAck(address=a))]
        if isinstance(m, M.StatusReq) and a == MMC:
            s = self.mmc
            return [(a, M.StatusAckMmc(gait=int(Gait.TRIPOD), direction=s["direction"], leg=s["leg"], error=s["error"]))]
        if isinstance(m, M.StatusReq):
            return [(a, M.StatusAckBusy(status=0))]
        if isinstance(m, M.PostQuery):
            short = {MMC: "MMC", SPU: "SPU"}[a]
            return [(a, M.PostReport(missing=[A[s] for s in self.reports.get(short, ())]))]
        if isinstance(m, M.XmitGrant) and self.records.get(a):
            return [(a, self.records[a].pop(0))]
        return []


def mcp(spec, until: float = 1.5, **kw) -> tuple[Rig, FirstBus]:
    bus = FirstBus(**kw)
    rig = Rig(spec, "MCP", MCP, bus)
    rig.run(until)
    return rig, bus


def send_record(rig, bus, src: int, rec: M.Message, at: float) -> None:
    bus.records.setdefault(src, []).append(rec)
    rig.inject(at, src, M.XmitReq())


def record(source: str, kind: RecordKind, value: int, channel: int = 0) -> M.XmitRecord:
    return M.XmitRecord(target=NP3, source=A[source], kind=int(kind), channel=channel, value=value, age=0)


def notes(rig, event: str):
    return [d for _t, e, d in rig.board.notes if e == event]


def lcd(rig, after: float = 0.0) -> list[str]:
    return [f.message.text.decode() for t, f in rig.frames(M.LcdText, UIC) if t >= after]


def spoken(rig, after: float = 0.0) -> list[int]:
    return [f.message.index for t, f in rig.frames(M.SpeakResident, SSC) if t >= after]


def test_post_verdict_is_shown_on_the_lcd(spec):
    rig, _ = mcp(spec)
    assert lcd(rig) == ["POST OPERATIONAL", "READY"]
    assert notes(rig, "operator_message")[0]["to"] == "operator"


def test_a_leg_error_goes_to_the_np3_once_per_change_and_to_the_operator(spec):
    rig, bus = mcp(spec)
    bus.mmc.update(error=int(MmcError.LEG_DRIVE_BLOCKED), leg=4)
    rig.run(1.5 + 4 * T.MCP_MMC_POLL_S)
    data = [f.message for _, f in rig.frames(M.Data, NP3) if f.message.address == MMC]
    # the first poll tells the NP3 the state (no error), then the change; nothing while it stays the same
    assert [(d.kind, d.channel, d.value) for d in data] == [(RecordKind.STATUS, 0, 0),
                                                            (RecordKind.STATUS, 4, MmcError.LEG_DRIVE_BLOCKED)]
    assert lcd(rig, 1.5) == ["LEG 4", "DRIVE BLOCKED"]
    assert spoken(rig) == [SscMessage.LEG_BLOCKED]
    bus.mmc.update(error=0, leg=0)
    rig.run(1.5 + 8 * T.MCP_MMC_POLL_S)
    data = [f.message for _, f in rig.frames(M.Data, NP3) if f.message.address == MMC]
    assert (data[-1].channel, data[-1].value) == (0, 0) and len(data) == 3


def test_unreliable_ir_and_failed_us_are_told_to_operator_and_supervisor(spec):
    rig, bus = mcp(spec)
    send_record(rig, bus, SPU, record("IRRC", RecordKind.STATUS, int(RangeStatus.UNRELIABLE)), 2.0)
    send_record(rig, bus, SPU, record("USRC", RecordKind.STATUS, int(RangeStatus.OUT_OF_ORDER)), 2.5)
    rig.run(3.0)
    relayed = [(f.message.address, f.message.kind, f.message.value) for _, f in rig.frames(M.Data, NP3)
               if f.message.address != MMC]
    assert relayed == [(A["IRRC"], RecordKind.STATUS, RangeStatus.UNRELIABLE),
                       (A["USRC"], RecordKind.STATUS, RangeStatus.OUT_OF_ORDER)]
    assert lcd(rig, 2.0) == ["IR UNRELIABLE", "ROBOT STOPPED", "US OUT OF ORDER", "DATA IGNORED"]
    msgs = notes(rig, "operator_message")[1:]
    assert [m["to"] for m in msgs] == ["operator", "supervisor"]          # seed 6.2
    assert spoken(rig) == [SscMessage.MALFUNCTION] * 2


def test_messages_go_only_to_nodes_present_after_post(spec):
    rig, bus = mcp(spec, silent=("SSC",))
    assert rig.node.verdict.verdict == "DEGRADED"
    send_record(rig, bus, SPU, record("IRRC", RecordKind.STATUS, int(RangeStatus.UNRELIABLE)), 2.0)
    rig.run(3.0)
    assert spoken(rig) == [] and rig.frames(M.SpeakResident) == []
    assert lcd(rig, 2.0) == ["IR UNRELIABLE", "ROBOT STOPPED"]
    assert notes(rig, "operator_message")[-1]["nodes"] == ["UIC/RCP"]


def test_whisker_contacts_are_announced_rate_limited(spec):
    rig, bus = mcp(spec)
    contact = int(TpscContact.OBJ_RIGHT)
    for at in (2.0, 3.0, 2.0 + T.MCP_OBSTACLE_SPEAK_S + 1):
        send_record(rig, bus, SPU, record("TPSC", RecordKind.VALUE, contact), at)
    rig.run(4.0 + T.MCP_OBSTACLE_SPEAK_S)
    assert spoken(rig) == [SscMessage.OBSTACLE_DETECTED] * 2
    assert len([f for _, f in rig.frames(M.Data, NP3) if f.message.address == A["TPSC"]]) == 3


def test_battery_alarm_beeps_and_blinks(spec):
    """seed 3.2.17: under-voltage: intermittent beep on the piezo and a blinking LED on the MCP."""
    rig, bus = mcp(spec)
    send_record(rig, bus, SPU, record("PSC", RecordKind.ALARM, 50), 2.0)
    rig.run(2.3)
    alarm = [f.message for _, f in rig.frames(M.Data, NP3) if f.message.address == A["PSC"]]
    assert [(d.kind, d.value) for d in alarm] == [(RecordKind.ALARM, 50)]      # the NP3's reflex stops the robot
    (_, f), = rig.frames(M.UicAlert, UIC)
    assert f.message.alert == Alert.BEEP | Alert.BLINK
    rig.run(2.3 + 10 * T.MCP_LED_BLINK_S)
    blinks = [(t, d["on"]) for t, e, d in rig.board.notes if e == "led_blink"]
    assert len(blinks) >= 9 and [on for _, on in blinks[:4]] == [True, False, True, False]
    assert abs((blinks[1][0] - blinks[0][0]) - T.MCP_LED_BLINK_S) < 1e-9


def test_post_halted_names_the_missing_nodes(spec):
    rig, _ = mcp(spec, silent=("MMC",))
    v = rig.node.verdict
    assert v.verdict == "HALTED"
    assert lcd(rig) == ["POST HALTED", "MISSING MMC"]
    assert spoken(rig) == [SscMessage.MALFUNCTION]
    assert rig.frames(M.Init) == []
    assert rig.node.debug_metrics()["lcd_line1"] == "MISSING MMC"


def test_post_again_at_run_time_from_the_uic(spec):
    """seed 6.3: POST_REQ from the UIC/RCP runs POST again; a passed POST starts navigation again (INIT)
    and the NP3 hears again what is known to be broken."""
    rig, bus = mcp(spec)
    send_record(rig, bus, SPU, record("IRRC", RecordKind.STATUS, int(RangeStatus.UNRELIABLE)), 2.0)
    ids_before = len(rig.frames(M.IdReq))
    send_record(rig, bus, UIC, M.PostReq(), 3.0)
    rig.run(5.0)
    assert len(rig.frames(M.IdReq)) == ids_before + len(FIRST)
    assert len(notes(rig, "post_verdict")) == 2
    inits = rig.frames(M.Init, BROADCAST)            # seed 3.2.3: INIT via broadcasting
    assert len(inits) == 2 and inits[1][0] > 3.0
    replay = [f.message for t, f in rig.frames(M.Data, NP3) if t > inits[1][0] and f.message.address == A["IRRC"]]
    assert [(d.kind, d.value) for d in replay] == [(RecordKind.STATUS, RangeStatus.UNRELIABLE)]


def test_post_halted_at_run_time_stops_the_robot_and_its_moves(spec):
    rig, bus = mcp(spec)
    bus.reports["SPU"] = ("TPSC",)
    send_record(rig, bus, UIC, M.PostReq(), 2.0)
    rig.run(4.0)
    assert rig.node.verdict.verdict == "HALTED"
    stop = [f.message for t, f in rig.frames(M.MoveRelayed, MMC) if t > 2.0]
    assert [(m.address, m.mov_cmd) for m in stop] == [(MCP, Direction.STOP)]
    send_record(rig, bus, NP3, M.Move(mov_cmd=int(Direction.FORWARD), param=0), 4.5)
    rig.run(5.5)
    assert [t for t, f in rig.frames(M.MoveRelayed, MMC) if t > 4.0] == []
    assert lcd(rig, 2.0)[-2:] == ["POST HALTED", "MISSING TPSC"]


def test_a_whisker_contact_stops_the_mmc_before_the_np3_hears_of_it(spec):
    """seed 5.2, spec reflexes whisker_stop: the MCP sends MOVE_RELAYED STOP ahead of its queue, then DATA."""
    rig, bus = mcp(spec)
    bus.mmc["direction"] = int(Direction.STOP)                          # the MMC confirms the STOP (no resend)
    rig.node.tell("operator", ("A", "B"), SscMessage.MALFUNCTION)      # own transactions waiting in the queue
    send_record(rig, bus, SPU, record("TPSC", RecordKind.VALUE, int(TpscContact.OBJ_LEFT)), 2.0)
    rig.run(3.0)
    stops = [(t, f) for t, f in rig.frames(M.MoveRelayed, MMC) if f.message.mov_cmd == int(Direction.STOP)]
    data = [t for t, f in rig.frames(M.Data, NP3) if f.message.address == A["TPSC"]]
    assert len(stops) == 1 and stops[0][1].message.address == A["TPSC"]
    assert data and stops[0][0] < data[0]
    assert not [t for t, _b, f in rig.sent if 2.0 < t < stops[0][0] and not isinstance(f.message, M.XmitGrant)], \
        "nothing of the MCP's own goes before the STOP"


def test_no_reflex_for_other_records_or_a_cleared_contact(spec):
    rig, bus = mcp(spec)
    send_record(rig, bus, SPU, record("TPSC", RecordKind.VALUE, 0), 2.0)          # contact gone
    send_record(rig, bus, SPU, record("IRRC", RecordKind.ALARM, 10, 1), 2.5)      # not a reflex source
    rig.run(3.5)
    assert not [f for _t, f in rig.frames(M.MoveRelayed, MMC) if f.message.mov_cmd == int(Direction.STOP)]


def test_a_granted_move_goes_through_the_generated_on_move_and_an_unasked_one_is_not_relayed(spec, monkeypatch):
    """issue 16 item 6: the MCP's MOVE path is the skeleton's on_move hook (seed 3.2.3); seed 3.2.2: a record
    counts only as the answer to the MCP's grant, so a MOVE the NP3 sends unasked moves nothing."""
    from behaviours.mcp import MCP as McpNode

    hooked = []
    relay = McpNode.on_move

    def spy(self, src, msg):
        hooked.append((src, msg.mov_cmd))
        relay(self, src, msg)
    monkeypatch.setattr(McpNode, "on_move", spy)
    rig, bus = mcp(spec)
    rig.inject(1.6, NP3, M.Move(mov_cmd=int(Direction.TURN_LEFT), param=0))       # no XMIT_REQ, no grant
    rig.run(1.9)
    assert hooked == [(NP3, int(Direction.TURN_LEFT))] and not rig.frames(M.MoveRelayed)
    assert notes(rig, "record_unasked")
    send_record(rig, bus, NP3, M.Move(mov_cmd=int(Direction.FORWARD), param=0), 2.0)
    rig.run(2.5)
    assert hooked[-1] == (NP3, int(Direction.FORWARD))
    assert [f.message.mov_cmd for _, f in rig.frames(M.MoveRelayed)][:1] == [int(Direction.FORWARD)]
