"""Issue 6.4: AVR firmware in simavr, alone and on a bus of the 2D simulator."""
from __future__ import annotations

import pytest
from arachnae_proto.enums import OrderStatus, RangeStatus, TpscContact
from arachnae_proto.network import ADDRESS_OF, BUSES, NODES

from tests.firmware.conftest import REPO

F = 16_000_000
MS = F // 1000
# the spec's addresses and sensor bus (seed 3.2.1), not literals: every fixture here is a sensor-bus slave,
# and sil/echo.c runs at that bus's rate too (the TPSC's build configuration)
TPSC, IRRC, LSC = ADDRESS_OF["TPSC"], ADDRESS_OF["IRRC"], ADDRESS_OF["LSC"]
SENSOR_BUS_INFO = BUSES[NODES[TPSC].bus]
SPU = ADDRESS_OF[SENSOR_BUS_INFO.master]
CHAR = F * SENSOR_BUS_INFO.bits_per_char // SENSOR_BUS_INFO.baud     # cycles per character


@pytest.fixture
def host_factory(firmware_built):
    from firmware.sil_bridge import SilHost
    hosts = []

    def make(elf):
        h = SilHost(firmware_built / elf)
        hosts.append(h)
        return h
    yield make
    for h in hosts:
        h.close()


def tx_bytes(events):
    return bytes(e[2] for e in events if e[0] == "t")


def run_like_the_bridge(host, until: int) -> list:
    """Run to `until`; as the board's latch, clear the collision-detect pin C2 when DE rises."""
    events = []
    while host.cycle < until:
        for e in host.run(until):
            events.append(e)
            if e[0] == "p" and e[2] == "D2" and e[3] == 1:
                host.set_pin("C2", 0)
    return events


def send(host, data: bytes):
    start = host.cycle
    for i, b in enumerate(data):
        host.inject(start + i * CHAR, b)


def test_echo_firmware_answers_one_character_time_after_each_byte(host_factory):
    h = host_factory("sil/echo.elf")
    h.run_until(MS)
    h.inject(2 * MS, 0x41)
    ev = h.run_until(60 * MS)
    (t,) = [e for e in ev if e[0] == "t"]
    assert t[2] == 0x42
    # RXC comes one (simavr) character time after the byte entered: 11 bits at the bus's rate
    assert 0.9 * CHAR < t[1] - 2 * MS < 1.2 * CHAR
    de = [(e[1], e[3]) for e in ev if e[0] == "p" and e[2] == "D2"]
    assert de[-2][1] == 1 and de[-1][1] == 0 and de[-2][0] < t[1] < de[-1][0]


def test_tpsc_firmware_answers_id_req_and_status_req_like_the_python_codec(host_factory):
    from arachnae_proto import frame, messages
    h = host_factory("avr/tpsc.elf")
    for pin in ("C0", "C1"):
        h.set_pin(pin, 1)
    h.set_pin("C2", 0)
    h.run_until(50 * MS)
    send(h, frame.build(TPSC, SPU, messages.IdReq()))
    out = tx_bytes(h.run_until(h.cycle + 80 * MS))
    assert out == frame.build(SPU, TPSC, messages.IdAck(address=TPSC))
    send(h, frame.build(TPSC, SPU, messages.StatusReq()))
    out = tx_bytes(h.run_until(h.cycle + 80 * MS))
    assert frame.parse(out).message == messages.StatusAckOrder(status=int(OrderStatus.IN_ORDER))   # seed 3.2.12: always
    # a request to another node, and one with a bad checksum, get no answer
    send(h, frame.build(IRRC, SPU, messages.IdReq()))
    bad = bytearray(frame.build(TPSC, SPU, messages.IdReq()))
    bad[-1] ^= 1
    h.run_until(h.cycle + 60 * MS)
    send(h, bytes(bad))
    assert tx_bytes(h.run_until(h.cycle + 80 * MS)) == b""


def test_tpsc_initiates_and_resends_after_a_corrupt_echo(host_factory, spec):
    """seed 3.2.12: the TPSC always initiates; seed 3.2.2 + address_backoff (scope all): after the corrupt echo
    it resends in its slot of the window (rank 0: the first) once the line was quiet for the window's idle time."""
    from arachnae_proto import frame, messages
    h = host_factory("avr/tpsc.elf")
    for pin in ("C0", "C1"):
        h.set_pin(pin, 1)
    h.set_pin("C2", 0)
    h.run_until(50 * MS)
    h.set_pin("C1", 0)                                  # right whisker touches
    ev, limit = [], h.cycle + 100 * MS
    while not any(e[0] == "p" and e[2] == "D2" and e[3] == 0 for e in ev) and h.cycle < limit:
        ev += h.run(limit)                              # stops at every byte and pin change
    assert tx_bytes(ev) == frame.build(SPU, TPSC, messages.DataRdy())
    released = next(e[1] for e in ev if e[0] == "p" and e[2] == "D2" and e[3] == 0)
    assert any(e[0] == "p" and e[2] == "B5" and e[3] == 1 for e in ev)   # stimulus test point
    from firmware.sil_bridge import hal_enum
    assert any(e[0] == "a" and e[2] == hal_enum("HAL_NOTE_")["REFLEX"] for e in ev)   # raised: tracecheck reflex_rate
    h.set_pin("C2", 1)                                  # the line released: the bus reports a corrupt echo
    ev = run_like_the_bridge(h, h.cycle + 150 * MS)
    again = [e for e in ev if e[0] == "t"]
    assert tx_bytes(ev) == frame.build(SPU, TPSC, messages.DataRdy())    # resent once, then its echo is good
    from behaviours.netconfig import NetConfig
    from behaviours.runtime import BusTiming, arbitration_rank, slave_quiet
    net, t = NetConfig.from_spec(spec), BusTiming(NODES[TPSC].bus)
    rank = arbitration_rank(net, NODES[TPSC].bus, TPSC)                   # spec rank_order
    quiet_ms = (again[0][1] - released) / MS
    # Runtime._slave_start inside the window after our corrupt frame: the line quiet for the window's idle
    # time, and the reflex source (rank 0) resends in the first slot of the window, which starts as our frame ends
    assert rank == 0
    assert slave_quiet(t, net, rank, True).in_window * 1e3 < quiet_ms < net.backoff_slots * t.slot_s * 1e3, quiet_ms
    send(h, frame.build(TPSC, SPU, messages.XmitData()))
    out = tx_bytes(run_like_the_bridge(h, h.cycle + 80 * MS))
    assert frame.parse(out).message == messages.XmitDataTpsc(contact=int(TpscContact.OBJ_RIGHT))
    assert 0 < h.stack_used() < 256


def test_high_obstacle_with_the_tpsc_in_simavr_behaves_like_the_python_run(firmware_built, spec):
    from sim2d.runner import run_sil
    from sim2d import runner
    from tracecheck.trace import trace_lines
    path = str(REPO / "scenarios" / "high_obstacle.yaml")
    python = runner.run(path, spec=spec)
    sil = run_sil(path, ("TPSC",), spec=spec)
    assert not python.failed, python.failed
    assert not sil.failed, sil.failed
    pm, sm = python.result.metrics, sil.result.metrics
    assert sm["post"]["verdict"] == pm["post"]["verdict"] == "OPERATIONAL"
    # the firmware took part: it answered POST and the SPU fetched whisker data from it
    sent = [line.split("\t")[6] for line in trace_lines([f for f in sil.result.frames if f.sender == "TPSC"])]
    assert any(s.startswith("ID_ACK") for s in sent), sent
    assert any(s.startswith("XMIT_DATA_TPSC") for s in sent), sent
    assert sm["max_reaction_s"] is not None and sm["max_reaction_s"] <= 1.0
    # the C TPSC writes the reflex_raised note too: its rate limit is checked, not skipped
    assert sm["protocol"]["checked"].get("reflex_rate", 0) >= 1 and sm["protocol"]["skipped"] == {}, sm["protocol"]


# ---- issue 15 part 3: the seven sensor controllers in C, the whole sensor bus as firmware ----------

SENSOR_BUS = ("USRC", "TPSC", "IRRC", "ISC", "TSC", "LSC", "PSC")


def test_sil_names_take_comma_lists_and_repeats_and_keep_a_node_name_s_comma():
    from firmware.sil_bridge import sil_names
    assert sil_names(["USRC,TPSC", "IRRC", "TPSC"]) == ["USRC", "TPSC", "IRRC"]
    assert sil_names(["JAC(1,1),TPSC"]) == ["JAC(1,1)", "TPSC"]


def test_sil_refuses_an_unknown_node_and_an_empty_list_in_one_line(spec):
    from arachnae.errors import UserError
    from firmware.sil_bridge import check_sil_nodes, sil_names
    with pytest.raises(UserError, match="--sil USRCX: no such node"):
        check_sil_nodes(spec, sil_names(["USRC,USRCX"]))
    with pytest.raises(UserError, match="no node given"):
        check_sil_nodes(spec, sil_names([","]))
    with pytest.raises(UserError, match="role MMC has no firmware"):
        check_sil_nodes(spec, ["MMC"])


def answer_port(host, until: int, reply) -> list:
    """Run like the bridge and answer every sensor-port request with reply(code, arg) (None: no reply)."""
    events = []
    while host.cycle < until:
        for e in host.run(until):
            events.append(e)
            if e[0] == "a":
                values = reply(e[2], e[3])
                if values is not None:
                    host.reply(values)
            elif e[0] == "p" and e[2] == "D2" and e[3] == 1:
                host.set_pin("C2", 0)
    return events


def test_irrc_firmware_three_plus_three_rule_declares_itself_unreliable(host_factory):
    """seed 3.2.13: readings spread too far twice -> UNRELIABLE; the last reliable value stays (CHOICE)."""
    from arachnae_proto import frame, messages
    from firmware.sil_bridge import hal_enum
    ir, status_note = hal_enum("HAL_SAMPLE_")["IR"], hal_enum("HAL_NOTE_")["STATUS"]
    h = host_factory("avr/irrc.elf")
    h.set_pin("C2", 0)
    reads = []

    def steady(code, arg):
        if code == ir:
            reads.append(code)
            return [100, 101, 100]
        return None
    ev = answer_port(h, 200 * MS, steady)
    # measures on its own clock (tuning.IRRC_MEASURE_S = 50 ms): 3 readings each, none spread
    assert 9 <= len(reads) <= 15, len(reads)
    assert not any(e[0] == "a" and e[2] == status_note for e in ev)
    toggle = [0]

    def spread(code, arg):
        if code == ir:
            toggle[0] ^= 1
            return [100 + 60 * toggle[0]] * 3        # 60 raw steps apart > IRRC_SPREAD_RAW 40
        return None
    ev = answer_port(h, h.cycle + 100 * MS, spread)
    notes = [e for e in ev if e[0] == "a" and e[2] == status_note]
    assert [e[3] for e in notes] == [int(RangeStatus.UNRELIABLE)]     # once
    send(h, frame.build(IRRC, SPU, messages.StatusReq()))
    out = tx_bytes(answer_port(h, h.cycle + 120 * MS, spread))
    # the DATA_RDY announcing the change may come first; the reply to STATUS_REQ is the last frame
    want = frame.build(SPU, IRRC, messages.StatusAckRange(status=int(RangeStatus.UNRELIABLE)))
    assert out[-len(want):] == want
    send(h, frame.build(IRRC, SPU, messages.XmitData()))
    out = tx_bytes(answer_port(h, h.cycle + 120 * MS, spread))
    want = frame.build(SPU, IRRC, messages.XmitDataIrrc(left=100, center=101, right=100))
    assert out[-len(want):] == want


def test_lsc_firmware_sends_the_mean_of_the_last_three_readings(host_factory):
    """seed 3.2.16: the value sent is the mean of the last three (half to even, as Python's round)."""
    from arachnae_proto import frame, messages
    from firmware.sil_bridge import hal_enum
    light = hal_enum("HAL_SAMPLE_")["LIGHT"]
    h = host_factory("avr/lsc.elf")
    h.set_pin("C2", 0)
    seq = iter([10, 20, 40, 70, 90] + [90] * 100)

    def reply(code, arg):
        return [next(seq)] if code == light else None
    answer_port(h, 850 * MS, reply)                    # readings at 0, 200, 400, 600, 800 ms
    send(h, frame.build(LSC, SPU, messages.XmitData()))
    out = tx_bytes(answer_port(h, h.cycle + 100 * MS, reply))
    assert frame.parse(out).message == messages.XmitDataLsc(brightness=round((40 + 70 + 90) / 3))


@pytest.mark.parametrize("scenario", ["fault_ir_unreliable", "fault_us_failed", "fault_battery"])
def test_fault_scenario_with_the_whole_sensor_bus_in_simavr_passes_like_python(firmware_built, spec, scenario):
    """issue 15: the seven sensor controllers as AVR firmware; same expectations and POST verdict as Python."""
    from sim2d.runner import run_sil
    from sim2d import runner
    path = str(REPO / "scenarios" / f"{scenario}.yaml")
    python = runner.run(path, spec=spec)
    made: list = []
    sil = run_sil(path, (",".join(SENSOR_BUS),), spec=spec, made=made)
    assert not python.failed, python.failed
    assert not sil.failed, sil.failed
    assert sil.result.metrics["post"]["verdict"] == python.result.metrics["post"]["verdict"]
    # every sensor was firmware and took part: it answered the SPU's POST and was fetched from
    assert sorted(n.node.short for n in made) == sorted(SENSOR_BUS)
    senders = {f.sender for f in sil.result.frames}
    assert set(SENSOR_BUS) <= senders
    for n in made:
        if n.host.proc.poll() is None:
            assert 0 < n.host.stack_used() < 512


def test_irrc_firmware_alarm_fires_once_per_crossing_and_rearms_with_hysteresis(host_factory):
    """seed 3.2.13 SET_ALARM: closer than the limit -> one alarm and a DATA_RDY to the SPU; it fires again only
    after the value was back ALARM_REARM_RAW steps beyond the limit (behaviours.sensors.AlarmLimit)."""
    from arachnae_proto import frame, messages
    from behaviours import tuning as T
    from firmware.sil_bridge import hal_enum
    ir, alarm = hal_enum("HAL_SAMPLE_")["IR"], hal_enum("HAL_NOTE_")["ALARM"]
    limit = messages.SetAlarmIrrc.from_phys(limit=T.SPU_ALARM_IRRC_CM).limit   # same encoding as the data
    rearm = T.ALARM_REARM_RAW["IRRC"]
    h = host_factory("avr/irrc.elf")
    h.set_pin("C2", 0)
    level = [limit + 50]

    def reply(code, arg):
        return [255, level[0], 255] if code == ir else None
    answer_port(h, 60 * MS, reply)
    send(h, frame.build(IRRC, SPU, messages.SetAlarmIrrc(limit=limit)))
    answer_port(h, h.cycle + 100 * MS, reply)

    def phase(value, ms=300):
        level[0] = value
        ev = answer_port(h, h.cycle + ms * MS, reply)
        return [e[3] for e in ev if e[0] == "a" and e[2] == alarm], tx_bytes(ev)
    fired, out = phase(limit - 1)
    assert fired == [0b010]                                  # the centre beam, once
    assert frame.build(SPU, IRRC, messages.DataRdy()) in out  # announced on its own
    assert phase(limit - 20)[0] == []                        # still beyond: no second alarm
    assert phase(limit + rearm - 1)[0] == []                 # back, but not far enough to re-arm
    assert phase(limit - 1)[0] == []
    assert phase(limit + rearm)[0] == []                     # re-armed ...
    assert phase(limit - 1)[0] == [0b010]                    # ... so the next crossing fires again
