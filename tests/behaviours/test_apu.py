"""APU/SDF node (seed 3.2.7, 4.3): a sound event becomes an XMIT_RECORD for the NP3; BUSY while processing."""
from __future__ import annotations

from arachnae_proto import messages as M
from arachnae_proto.enums import BusyStatus, RecordKind
from arachnae_proto.network import ADDRESS_OF

from behaviours import tuning as T
from tests.behaviours.rig import Rig

MCP, NP3, APU = ADDRESS_OF["MCP"], ADDRESS_OF["NP3"], ADDRESS_OF["APU/SDF"]


def grant(frame):
    """The MCP's side of message scheduling (seed 3.2.2): every XMIT_REQ is granted."""
    return [(MCP, M.XmitGrant())] if isinstance(frame.message, M.XmitReq) else []


def apu(spec, events: list, respond=grant) -> Rig:
    """An APU/SDF on the bench; its microphones report `events`: (time, (direction deg, level dB))."""
    rig = Rig(spec, "APU_SDF", APU, respond)
    pending = list(events)
    rig.board.sound_event = lambda: pending.pop(0)[1] if pending and pending[0][0] <= rig.board.t else None
    return rig


def records(rig: Rig) -> list[M.XmitRecord]:
    return [f.message for _t, f in rig.frames(M.XmitRecord, MCP)]


def test_sound_direction_reaches_the_np3_as_a_record(spec):
    rig = apu(spec, [(0.1, (90.4, 65.3)), (1.0, (359.7, 300.0)), (2.0, (200.0, T.APU_MIN_LEVEL_DB - 1))])
    rig.run(3.0)
    got = [(r.target, r.source, r.kind, r.channel, r.value) for r in records(rig)]
    assert got == [(NP3, APU, RecordKind.VALUE, 90, 65),          # body frame, ccw from forward; dB
                   (NP3, APU, RecordKind.VALUE, 0, 255)]           # 359.7 deg rounds to 0; level clamped
    assert len(rig.frames(M.XmitReq, MCP)) == 2                    # each record asked for the bus first
    assert rig.node.debug_metrics() == {"events_heard": 2, "events_too_quiet": 1, "records_sent": 2}
    # the record is sent only after the processing time
    t_req = rig.frames(M.XmitReq, MCP)[0][0]
    assert t_req >= 0.1 + T.APU_PROCESS_S - 1e-9


def test_status_is_busy_while_processing(spec):
    rig = apu(spec, [(0.1, (45.0, 70.0))])
    rig.inject(0.1 + T.APU_PROCESS_S / 2 + T.APU_POLL_S, MCP, M.StatusReq())
    rig.inject(1.0, MCP, M.StatusReq())
    rig.run(1.5)
    acks = [f.message.status for _t, f in rig.frames(M.StatusAckBusy, MCP)]
    assert acks == [BusyStatus.BUSY, BusyStatus.NOT_BUSY]


def test_a_record_lost_on_the_way_is_sent_again_on_the_repeated_grant(spec):
    def grant_twice(frame):
        if isinstance(frame.message, M.XmitReq):
            return [(MCP, M.XmitGrant()), (MCP, M.XmitGrant())]   # the MCP did not get the first record
        return []
    rig = apu(spec, [(0.1, (180.0, 80.0))], grant_twice)
    rig.run(1.0)
    assert [(r.channel, r.value) for r in records(rig)] == [(180, 80), (180, 80)]
