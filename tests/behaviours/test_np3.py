"""NP3 node (seed 3.2.3, 5.2, 6, docs/decisions.md D8): DATA records in, MOVE records out, through its subsumption network."""
from __future__ import annotations

import math
from collections import deque

import pytest
from PIL import Image

from arachnae_proto import messages as M
from arachnae_proto.enums import MmcError, MovCmd, RangeStatus, RecordKind, TpscContact
from arachnae_proto.network import ADDRESS_OF
from behaviours import tuning as T
from behaviours.geometry import DEFAULT_GEOMETRY
from behaviours.np3 import DeadReckoning, Echo, GaitReckoning, Ping, decode
from behaviours.np3_layers import (LSC_STEP_LOG, TaskModule, Tuning, body_frame, clear_ahead, light_gradient, np3_network,
                                   wall_beside)
from behaviours.units import age_byte, quantizer
from tests.behaviours.rig import Rig

MCP, NP3 = ADDRESS_OF["MCP"], ADDRESS_OF["NP3"]
VALUE, ALARM, STATUS = int(RecordKind.VALUE), int(RecordKind.ALARM), int(RecordKind.STATUS)


def grant(frame):
    """The MCP grants every XMIT_REQ at once (seed 3.2.2 message scheduling)."""
    return [(MCP, M.XmitGrant())] if isinstance(frame.message, M.XmitReq) else []


IR_CLEAR = quantizer(M.XmitDataIrrc, "center").hi     # an IR beam that sees nothing within its range


def np3(spec, task: str = "forward", ir_first: bool = True) -> Rig:
    """The NP3 with INIT at 0.05 s; `ir_first`: the SPU's first polls of the IR (nothing in range) and the
    whiskers (no contact) reach it before (tuning.SPU_FIRST_POLL)."""
    rig = Rig(spec, "NP3", NP3, grant, task=task)
    if ir_first:
        rig.inject(0.03, MCP, data("IRRC", IR_CLEAR))
        rig.inject(0.04, MCP, data("TPSC", 0))
    rig.inject(0.05, MCP, M.Init())
    return rig


def data(role: str, value: int, kind: int = VALUE, channel: int = 0, age_s: float = 0.0) -> M.Data:
    return M.Data(address=ADDRESS_OF[role], kind=kind, channel=channel, value=value, age=age_byte(age_s))


def moves(rig: Rig) -> list[tuple[float, MovCmd]]:
    return [(t, MovCmd(f.message.mov_cmd)) for t, f in rig.frames(M.Move, MCP)]


def command_at(rig: Rig, t: float) -> MovCmd:
    return [m for at, m in moves(rig) if at <= t][-1]


def test_init_starts_the_task_and_a_whisker_contact_backs_off_within_the_reaction_time(spec):
    rig = np3(spec)
    rig.run(1.0)
    assert moves(rig) == [(pytest.approx(0.05, abs=0.05), MovCmd.FORWARD)]
    rig.inject(2.0, MCP, data("TPSC", int(TpscContact.OBJ_BOTH)))          # head-on contact
    manoeuvre = T.NP3_CONTACT_BACK_S + (90 + T.NP3_CONTACT_CLEAR_DEG) / T.NP3_DR_TURN_DEG_S   # back, turn ~110 deg
    end = 2.0 + manoeuvre + 0.5 + 0.5                  # the 0.5 s hold and a little more
    rig.run(end)
    after = [(t, m) for t, m in moves(rig) if t >= 2.0]
    assert after[0][1] == MovCmd.BACKWARD and after[0][0] - 2.0 < 0.1     # seed 5.2: well within 1 s
    assert any(m in (MovCmd.TURN_LEFT, MovCmd.TURN_RIGHT) for _t, m in after[1:])
    assert command_at(rig, end - 1.0) != MovCmd.FORWARD   # still turning away from the surface ahead
    assert command_at(rig, end) == MovCmd.FORWARD         # back to the task after the manoeuvre and the hold
    metrics = rig.node.debug_metrics()
    assert set(metrics["control"]) == {"task", "reflexes"}
    assert sum(metrics["control"].values()) == pytest.approx(end - 0.05, abs=0.15)
    assert metrics["control"]["reflexes"] == pytest.approx(manoeuvre + 0.5, abs=0.15)
    assert metrics["switches"] == 2 and metrics["takeovers"]["contact"] == 1


def test_switched_on_the_first_step_waits_for_what_the_ir_sees(spec):
    """seed 5.2: next to a wall at power-on the robot must not walk before its close range is known: no MOVE
    after INIT until the IR's and the whiskers' first records, at once after them; without, after NP3_START_LOOK_S."""
    rig = np3(spec, ir_first=False)
    rig.inject(0.3, MCP, data("IRRC", IR_CLEAR, channel=1))
    rig.run(0.5)
    assert moves(rig) == []                             # the IR alone: the whiskers may still touch something
    rig.inject(0.6, MCP, data("TPSC", 0))
    rig.run(1.0)
    assert moves(rig)[0][1] == MovCmd.FORWARD and 0.6 < moves(rig)[0][0] <= 0.6 + T.NP3_PERIOD_S + 0.02   # next period
    silent = np3(spec, ir_first=False)                  # the IRRC never reports (absent, or its bus broken)
    silent.run(0.05 + T.NP3_START_LOOK_S - 0.1)
    assert moves(silent) == []
    silent.run(0.05 + T.NP3_START_LOOK_S + 0.15)
    assert [m for _t, m in moves(silent)] == [MovCmd.FORWARD]


def test_left_whisker_turns_right_without_backing_off(spec):
    """seed 3.2.12: OBJ_LEFT -> away to the right. The touch may be on the left feeler's lane wire ahead of the
    face (docs/decisions.md D18), so the motion check steps the body aside before the turn that would sweep the
    face into it; never back into what may lie behind."""
    rig = np3(spec)
    rig.inject(1.0, MCP, data("TPSC", int(TpscContact.OBJ_LEFT)))
    rig.run(4.0)
    after = [m for t, m in moves(rig) if t >= 1.0]
    assert after[:2] == [MovCmd.SIDESTEP_RIGHT, MovCmd.TURN_RIGHT]


def test_a_feeler_touch_leaves_all_its_wires_in_the_memory_the_motion_check_steers_by(spec):
    """docs/decisions.md D18: the left switch says only that a wire of the left feeler touched something, so the
    local memory gets points near the root, middle and tip of every wire: beside the front corner (the outer
    and the side wire) and across the body's lane ahead of the face (the inner wire). A thin post met by the inner wire is
    then in the memory where the turn away would sweep the face into it (posts_low)."""
    rig = np3(spec, task="idle")
    rig.inject(1.0, MCP, data("TPSC", int(TpscContact.OBJ_LEFT)))
    rig.run(1.01)
    pts = body_frame(tuple(e.point() for e in rig.node.echoes), (0.0, 0.0, 0.0))
    half_w = DEFAULT_GEOMETRY.body_width / 2
    lane = [p for p in pts if p[0] > T.NP3_BODY_FRONT_M + 0.035 and 0.0 < p[1] < half_w]
    beside = [p for p in pts if p[1] > half_w]
    assert len(lane) >= 2 and len(beside) == 6, pts         # the outer and the side wire's
    assert all(p[1] > 0 for p in pts)                       # the left feeler's only


def test_a_touch_beside_a_wall_the_sonar_shows_is_the_side_wire_and_steps_away_from_it(spec):
    """docs/decisions.md D18: a wall along the way meets the side wire's tip first (the feelers' point
    furthest out). With a wall alongside on the touched side in the sonar's memory (corridor_narrow:
    0.5 m wide, the side wire reaching 17.7 cm beside the axis) the touch is that wall: one point at the wire's
    tip, none across the lane ahead (they read as a blocked way and avoidance turned the body across the
    corridor), and the escape a sidestep away from it, no turn. Without the sonar's wall the same touch leaves
    both wires' points (a post lower than the sonar head: the test above)."""
    metres = quantizer(M.XmitDataUsrc, "distance")
    rig = np3(spec, task="idle")
    for k, head in enumerate((270, 285, 300)):                   # the right-hand wall 0.2 m beside the axis
        rig.inject(0.5 + k / 10, MCP, data("USRC", metres.raw(0.2 / math.sin(math.radians(360 - head))), VALUE,
                                            channel=head))
    rig.inject(1.0, MCP, data("TPSC", int(TpscContact.OBJ_RIGHT)))
    rig.run(1.01)
    touch = [e for e in rig.node.echoes if not e.sonar]
    pts = body_frame(tuple(e.point() for e in touch), (0.0, 0.0, 0.0))
    tip = T.NP3_WHISKER_ARMS[1][-1]                              # the side wire's, 17.7 cm beside the axis
    assert [(round(bx, 4), round(by, 4)) for bx, by, _s, _a in pts] == [(tip.x, -tip.y)]
    rig.run(3.0)
    after = [m for t, m in moves(rig) if t >= 1.0]
    assert after[0] == MovCmd.SIDESTEP_LEFT and MovCmd.TURN_LEFT not in after and MovCmd.TURN_RIGHT not in after


def test_unreliable_ir_stops_the_robot_and_a_contact_cannot_restart_it(spec):
    rig = np3(spec)
    rig.inject(1.0, MCP, data("IRRC", int(RangeStatus.UNRELIABLE), STATUS))
    rig.inject(3.0, MCP, data("TPSC", int(TpscContact.OBJ_LEFT)))
    rig.run(8.0)
    assert command_at(rig, 1.2) == MovCmd.STOP                               # seed 6.2
    assert all(m == MovCmd.STOP for t, m in moves(rig) if t >= 1.0)
    rig.inject(8.5, MCP, data("IRRC", int(RangeStatus.IN_ORDER), STATUS))
    rig.run(15.0)
    assert command_at(rig, 10.0) != MovCmd.STOP                              # moving again; first away from
    assert command_at(rig, 15.0) == MovCmd.FORWARD                           # the touch it still remembers


def test_battery_alarm_stops_for_good(spec):
    rig = np3(spec)
    volts = quantizer(M.XmitDataPsc, "voltage")
    rig.inject(1.0, MCP, data("PSC", volts.raw(4.6), VALUE))
    rig.run(2.0)
    assert command_at(rig, 2.0) == MovCmd.FORWARD
    rig.inject(2.5, MCP, data("PSC", volts.raw(4.25), ALARM))                # seed 3.2.17: under-voltage
    rig.inject(4.0, MCP, data("PSC", volts.raw(4.6), VALUE))
    rig.run(30.0)
    assert command_at(rig, 2.6) == MovCmd.STOP and command_at(rig, 30.0) == MovCmd.STOP
    assert rig.node.debug_metrics()["battery_low"] is True


def test_pit_backs_off_once_per_report_and_blocked_leg_holds_still(spec):
    rig = np3(spec)
    rig.inject(1.0, MCP, data("MMC", int(MmcError.NO_GROUND), STATUS, channel=1))
    rig.run(1.5)
    assert command_at(rig, 1.5) == MovCmd.BACKWARD
    rig.run(12.0)
    assert command_at(rig, 12.0) == MovCmd.FORWARD                           # the report stays; no second escape
    assert sum(1 for t, m in moves(rig) if m == MovCmd.BACKWARD) == 1
    rig.inject(12.5, MCP, data("MMC", int(MmcError.LEG_DRIVE_BLOCKED), STATUS, channel=4))
    rig.run(12.8)
    assert command_at(rig, 12.8) == MovCmd.STOP                              # seed 6.1: let the LCP re-plan


def test_tilt_values_are_twos_complement_and_a_steep_slope_is_refused(spec):
    deg = quantizer(M.XmitDataIsc, "longitudinal")
    assert decode("ISC", (-30) & 0xFF) == pytest.approx(-30.0)
    rig = np3(spec)
    rig.inject(1.0, MCP, data("ISC", deg.raw(12), VALUE, channel=0))         # a gentle slope: walk on
    rig.run(2.0)
    assert command_at(rig, 2.0) == MovCmd.FORWARD
    rig.inject(2.5, MCP, data("ISC", deg.raw(36), ALARM, channel=0))         # nose up, too steep: back down
    rig.run(3.0)
    assert command_at(rig, 3.0) == MovCmd.BACKWARD


def test_sonar_ahead_makes_it_avoid_unless_the_usrc_is_declared_unreliable(spec):
    metres = quantizer(M.XmitDataUsrc, "distance")
    rig = np3(spec)
    rig.inject(1.0, MCP, data("USRC", metres.raw(0.25), VALUE, channel=2))   # head 2 deg off the axis
    rig.run(1.5)
    assert command_at(rig, 1.5) in (MovCmd.TURN_LEFT, MovCmd.TURN_RIGHT)
    rig2 = np3(spec)
    rig2.inject(0.5, MCP, data("USRC", int(RangeStatus.UNRELIABLE), STATUS))  # seed 6.2: ignore its data
    rig2.inject(1.0, MCP, data("USRC", metres.raw(0.25), VALUE, channel=2))
    rig2.run(3.0)
    assert [m for _t, m in moves(rig2)] == [MovCmd.FORWARD]


def test_a_sound_to_the_left_turns_the_robot_towards_it(spec):
    rig = np3(spec, task="idle")
    rig.inject(1.0, MCP, data("APU/SDF", 70, VALUE, channel=90))             # 90 deg to the left
    rig.run(10.0)
    turn = [t for t, m in moves(rig) if m == MovCmd.TURN_LEFT]
    stop = [t for t, m in moves(rig) if m == MovCmd.STOP and t > 1.0]
    assert turn and stop
    assert stop[0] - turn[0] == pytest.approx(90 / T.NP3_DR_TURN_DEG_S + 0.3, abs=0.3)   # turn + suppressor hold


def test_artifacts_hold_the_control_trace_and_the_map(spec, tmp_path):
    metres = quantizer(M.XmitDataUsrc, "distance")
    rig = np3(spec, task="explore")
    for k in range(0, 360, 5):                                               # a sweep: walls 1.5 m around
        rig.inject(1.0 + k / 100, MCP, data("USRC", metres.raw(1.5), VALUE, channel=k))
    rig.run(12.0)
    rig.node.write_artifacts(tmp_path)
    rows = (tmp_path / "control.tsv").read_text().splitlines()
    assert rows[0] == "start_s\tend_s\tlayer\tmodule" and len(rows) >= 2
    assert float(rows[-1].split("\t")[1]) == pytest.approx(12.0, abs=0.01)
    img = Image.open(tmp_path / "topomap.png")
    assert img.size[0] > 100
    assert rig.node.debug_metrics()["map"]["seen_m2"] > 3.0                  # the sweep crossed the room
    rgb = img.convert("RGB")                                                 # the plan followed now is drawn
    assert any(rgb.getpixel((u, v)) == (0, 170, 60) for u in range(0, rgb.width, 2) for v in range(rgb.height))
    plans = (tmp_path / "plans.tsv").read_text().splitlines()               # every plan, with its route
    assert plans[0] == "t_s\tx_m\ty_m\tkind\tfresh_m\troute" and len(plans) == 1 + len(rig.node.plans) >= 3
    t, _x, _y, kind, _fresh, route = plans[-1].split("\t")
    goal = tuple(float(v) for v in route.split()[-1].split(","))
    assert kind == "heading" and goal == pytest.approx(rig.node.goal, abs=0.01) and 10.0 <= float(t) <= 12.0


def test_dead_reckoning_and_light_gradient():
    odo = DeadReckoning(0.1, math.radians(25))
    odo.command(0.0, int(MovCmd.FORWARD))
    odo.command(10.0, int(MovCmd.TURN_LEFT))
    odo.command(13.6, int(MovCmd.FORWARD))
    odo.advance(23.6)
    x, y, th = odo.pose
    assert (x, y, math.degrees(th)) == pytest.approx((1.0, 1.0, 90.0), abs=1e-6)
    # brighter towards +y: the fitted slope points there; samples on a line give no gradient
    samples = [(x, y, 1.0 + 0.5 * y) for x, y in ((0, 0), (1, 0), (1, 1), (0, 1))]
    gx, gy = light_gradient(samples, 0.25)
    assert gx == pytest.approx(0.0, abs=1e-9) and gy == pytest.approx(0.5)
    assert light_gradient([(0, 0, 1.0), (1, 0, 1.1), (2, 0, 1.2)], 0.25) is None


def test_a_later_light_fit_corrects_along_the_way_and_keeps_the_prior_across_it():
    # samples on a line along x: alone they fit no plane; with the last fit as prior the slope along x
    # follows the samples (towards 0.2) and the slope across (y) stays the prior's
    line = [(0.1 * k, 0.0, 1.0 + 0.02 * k) for k in range(8)]
    assert light_gradient(line, 0.15) is None
    gx, gy = light_gradient(line, 0.15, prior=(0.0, 0.5))
    assert 0.1 < gx < 0.2 and gy == pytest.approx(0.5)


def test_seek_light_samples_while_probing_and_stops_the_probe_once_the_gradient_is_known():
    task = TaskModule("seek_light", Tuning())
    brighter_up = lambda x, y: 1.0 + 0.2 * y          # noqa: E731
    path = [(0.0, 0.0), (0.3, 0.0), (0.6, 0.0), (0.6, 0.0), (0.6, 0.3), (0.6, 0.6)]
    now, probing = 0.0, None
    for seq, (x, y) in enumerate(path, 1):
        out = task.step({"light": (seq, x, y, brighter_up(x, y)), "pose": (x, y, 0.0)}, now)
        probing = probing if probing is not None else task.plan
        now += 2.5
    assert probing is not None and len(task.samples) == len(path)   # every sample counted, also during the probe
    gx, gy = task.gradient
    assert math.degrees(math.atan2(gy, gx)) == pytest.approx(90.0, abs=1.0)
    assert task.plan is None or task.plan is not probing                 # the probe was dropped
    assert out["move"] in (MovCmd.TURN_LEFT, MovCmd.FORWARD)           # ... for the light (+y: turn left)


@pytest.mark.parametrize("rise, steers_to_goal", [(0.0, True), (0.05, False)])
def test_seek_light_explores_towards_the_planned_goal_while_no_sample_shows_a_light(rise, steers_to_goal):
    """A lamp shaded by a wall: the samples read the same everywhere, so the task layer follows the map's
    goal (a route to the nearest frontier) instead of a gradient that is not there; a real gradient wins."""
    t = Tuning()
    task = TaskModule("seek_light", t)
    goal = (0.0, -3.0)                                    # to the right of a robot facing +x
    now = 0.0
    for seq in range(1, t.light_samples + 1):            # an L of samples; log lux rises along +x by `rise`/step
        x, y = (0.3 * seq, 0.0) if seq <= 4 else (1.2, 0.3 * (seq - 4))
        task.plan = None
        out = task.step({"light": (seq, x, y, 1.0 + rise * seq), "pose": (x, y, 0.0), "goal": goal}, now)
        now += 2.5
    assert task.dark() == steers_to_goal
    task.plan = None
    out = task.step({"pose": (1.2, 1.2, 0.0), "goal": goal}, now)
    assert (out["move"] == MovCmd.TURN_RIGHT) == steers_to_goal


def test_seek_light_darkness_holds_through_noise_ends_at_a_brighter_sample_and_not_at_a_bright_plateau():
    """seed 3.2.16: a shaded room reads the ambient light give or take 2 LSC steps; that is dark (explore the
    map) for as long as it lasts, not a gradient to climb. A sample 8 steps brighter (the lamp seen past the
    wall's end) ends it; readings flat at the lamp (the LSC saturated) are not dark: the light is here."""
    t = Tuning()
    task = TaskModule("seek_light", t)
    assert t.light_flat_log > 2 * LSC_STEP_LOG
    noise = [0, 2, 1, 0, 2, 1, 0, 2, 1, 2, 0, 1, 2, 0, 2, 1]
    seq = 0

    def sample(log_lux: float) -> None:
        nonlocal seq
        seq += 1
        x, y = 0.3 * (seq % 4), 0.3 * (seq // 4 % 4)          # spread in both directions: a fit is possible
        task.step({"light": (seq, x, y, log_lux), "pose": (x, y, 0.0)}, 2.5 * seq)

    for k, n in enumerate(noise):
        sample(0.7 + n * LSC_STEP_LOG)
        assert task.dark() == (k + 1 >= t.light_samples)       # dark from the first full set on, and it holds
    assert task.gradient is None                               # no gradient fitted to the noise
    sample(0.7 + 8 * LSC_STEP_LOG)
    assert not task.dark()
    for _k in range(2 * t.light_samples):                      # at the lamp: flat, but far above the ambient
        sample(3.0)
        assert not task.dark()


def test_seek_light_walks_round_an_obstacle_on_one_side():
    t = Tuning()
    task = TaskModule("seek_light", t)
    # a wall 0.4 m ahead across the light's bearing (+x), 1.2 m long
    wall = tuple((0.4, -0.6 + 0.05 * k, 0.0, 0.0) for k in range(25))
    h1 = task._detour({"echoes": wall}, (0.0, 0.0, 0.0), 0.0, 0.0)
    assert abs(math.degrees(h1)) >= 40                                  # not into the wall
    assert clear_ahead(body_frame(wall, (0.0, 0.0, h1)), t.avoid_half_width_m) >= t.light_clear_m
    side = math.copysign(1.0, h1)
    # a little later the target swings to the other side of the bearing: the detour keeps its side
    h2 = task._detour({"echoes": wall}, (0.0, 0.0, h1), -side * math.radians(t.light_weave_deg), 2.0)
    assert math.copysign(1.0, h2) == side
    # nothing in the way: straight for the target
    assert task._detour({"echoes": ()}, (0.0, 0.0, 0.0), 0.3, 20.0) == 0.3


def test_a_detour_keeps_clear_of_the_mapped_obstacle_the_echo_memory_has_let_go():
    t = Tuning()
    wall = tuple((0.4, -0.6 + 0.05 * k, 0.0, 0.0) for k in range(25))     # the same wall, now only on the map
    task = TaskModule("seek_light", t)
    assert task._detour({"echoes": (), "mapped": ()}, (0.0, 0.0, 0.0), 0.0, 0.0) == 0.0
    h = task._detour({"echoes": (), "mapped": wall}, (0.0, 0.0, 0.0), 0.0, 0.0)
    assert abs(math.degrees(h)) >= 40
    assert clear_ahead(body_frame(wall, (0.0, 0.0, h)), t.avoid_half_width_m) >= t.light_clear_m


def test_the_node_senses_the_mapped_obstacles_round_it(spec):
    metres = quantizer(M.XmitDataUsrc, "distance")
    rig = np3(spec, task="seek_light")
    for k in range(0, 360, 5):                                               # walls 0.8 m all round
        rig.inject(0.1 + k / 400, MCP, data("USRC", metres.raw(0.8), VALUE, channel=k))
    rig.run(2.0)
    mapped = rig.node.layers.sensors["mapped"]
    assert mapped and all(0.6 < math.hypot(mx, my) <= T.NP3_MAPPED_NEAR_M for mx, my, _s, _a in mapped)


def test_dead_reckoning_counts_sidesteps():
    odo = DeadReckoning(0.1, math.radians(25), 0.08)
    odo.command(0.0, int(MovCmd.TURN_LEFT))
    odo.command(3.6, int(MovCmd.SIDESTEP_RIGHT))          # facing +y: a sidestep right goes to +x
    odo.command(13.6, int(MovCmd.STOP))
    odo.advance(20.0)
    assert odo.pose == pytest.approx((0.8, 0.0, math.radians(90)), abs=1e-6)


def test_a_blocked_right_leg_holds_then_steps_left_away_from_it(spec):
    rig = np3(spec)
    rig.inject(1.0, MCP, data("MMC", int(MmcError.LEG_DRIVE_BLOCKED), STATUS, channel=5))   # legs 4..6: right
    rig.run(4.0)
    after = [m for t, m in moves(rig) if t >= 1.0]
    assert after[:2] == [MovCmd.STOP, MovCmd.SIDESTEP_LEFT]                 # seed 6.1, then away from it
    assert command_at(rig, 4.0) == MovCmd.FORWARD


def _wall(y: float, x0: float = -1.0, x1: float = 0.6, seen: float = -90.0, arc: float = 0.04):
    """Echo points of a straight wall along x at height y (body frame = world frame at pose 0)."""
    return tuple((x0 + k * 0.1, y, seen, arc) for k in range(int(round((x1 - x0) / 0.1)) + 1))


def test_wall_beside_and_the_corridor_ahead_from_remembered_echoes():
    pose = (0.0, 0.0, 0.0)
    dist, angle = wall_beside(body_frame(_wall(-0.3), pose))
    assert dist == pytest.approx(0.3) and angle == pytest.approx(0.0, abs=1e-9)
    slanted = tuple((x, -0.3 + 0.1 * x, s, a) for x, _y, s, a in _wall(-0.3))   # nearer ahead: turn left
    assert wall_beside(body_frame(slanted, pose))[1] == pytest.approx(-math.atan(0.1))
    # a slanted sonar echo 1.1 m ahead may come from the side wall (wide arc): not an obstacle ahead ...
    assert clear_ahead(body_frame(((1.1, -0.19, -10.0, 0.15),), pose), 0.25) == math.inf
    # ... a narrow one (IR, or the sonar looking straight at a wall) is
    assert clear_ahead(body_frame(((0.4, 0.05, 0.0, 0.05),), pose), 0.25) == pytest.approx(0.4)
    # the memory is in world terms: turned by 90 degrees, the wall on the right is now behind
    assert clear_ahead(body_frame(((0.4, 0.0, 0.0, 0.0),), (0.0, 0.0, math.pi / 2)), 0.25) == math.inf


@pytest.mark.parametrize("wall_y, ahead, expected", [
    (-0.45, (), MovCmd.SIDESTEP_RIGHT),                 # too far from the wall: step towards it
    (-0.18, (), MovCmd.SIDESTEP_LEFT),                  # the feet would reach it: step away
    (-0.30, (), MovCmd.FORWARD),                        # in the band: walk on
    (-0.30, ((0.4, 0.0, 0.0, 0.05),), MovCmd.TURN_LEFT),   # a wall ahead: an inside corner, turn with it
])
def test_wall_following_holds_the_band_with_sidesteps_and_turns_at_corners(wall_y, ahead, expected):
    clock = [0.0]
    net = np3_network(lambda: clock[0], "wall_follow")
    net.sense(pose=(0.0, 0.0, 0.0), echoes=_wall(wall_y) + ahead)
    assert net.step()["move"] == expected


def test_exploring_sets_a_goal_short_of_the_mapped_walls(spec):
    metres = quantizer(M.XmitDataUsrc, "distance")
    rig = np3(spec, task="explore")
    # walls 1.5 m all round, swept twice: the robot turns to its first goal meanwhile (the dead reckoning
    # through the gait model), so one sweep left a hole of that turn where it began and ended, and the
    # 10 s plan went out through it
    for k in range(0, 720, 5):
        rig.inject(0.1 + k / 400, MCP, data("USRC", metres.raw(1.5), VALUE, channel=k % 360))
    rig.run(11.0)                                                            # the 10 s re-plan saw the sweep
    goal = rig.node.goal
    x, y, _th = rig.node.odo.pose
    assert goal is not None and math.hypot(goal[0] - x, goal[1] - y) > 0.3
    assert math.hypot(*goal) < 1.5 - 0.1                                     # inside the walls, short of them


def test_the_motion_check_refuses_only_moves_that_close_in_on_an_echo():
    from behaviours.np3_layers import closing_in, safe_instead
    t = Tuning()
    behind = [(-0.2, 0.0, 180.0, 0.0)]                     # 5 cm behind the rear edge
    assert closing_in(behind, MovCmd.BACKWARD, t) > 0
    assert closing_in(behind, MovCmd.FORWARD, t) == 0      # moving away from it is always allowed
    corner = [(0.1, 0.13, 50.0, 0.0)]                       # 5 cm beside the front of the left flank
    assert closing_in(corner, MovCmd.TURN_LEFT, t) > 0     # the corner swings into it
    assert closing_in(corner, MovCmd.TURN_RIGHT, t) == 0
    assert safe_instead(corner, MovCmd.TURN_LEFT, t) == MovCmd.TURN_RIGHT
    boxed = [(0.2, 0.0, 0.0, 0.0), (-0.2, 0.0, 180.0, 0.0), (0.0, 0.11, 90.0, 0.0), (0.0, -0.11, -90.0, 0.0),
             (0.17, 0.1, 30.0, 0.0), (0.17, -0.1, -30.0, 0.0)]
    assert safe_instead(boxed, MovCmd.FORWARD, t) == MovCmd.STOP     # nothing is safe: stand still
    far = [(1.5, 0.0, 0.0, 0.05)]
    assert all(closing_in(far, c, t) == 0 for c in MovCmd)
    # a wall along the left flank that closes in ahead: turning right swings the rear into it, and turning left
    # (towards it) is what avoidance had turned away from: sidestep away from it (scenarios/sonar_first.yaml)
    flank = [(x / 20, 0.14 - (x / 20 + 0.2) * 0.05, 90.0, 0.0) for x in range(-4, 7)]    # 6 cm off the rear corner
    assert closing_in(flank, MovCmd.TURN_RIGHT, t) > 0 and closing_in(flank, MovCmd.SIDESTEP_RIGHT, t) == 0
    assert safe_instead(flank, MovCmd.TURN_RIGHT, t) == MovCmd.SIDESTEP_RIGHT


def test_a_refused_walk_turns_away_from_what_it_would_close_in_on():
    """corridor_narrow seed 3: walking 10 deg off a corridor's axis, the right-hand wall's echo 0.27 m ahead-right
    refused FORWARD; the left-hand wall alongside had more echoes near the body, and turning towards the freer
    side by their count turned the robot right, into the wall ahead."""
    from behaviours.np3_layers import closing_in, safe_instead
    t = Tuning()
    ahead_right = (0.272, -0.084, -11.0, 0.085)
    left_wall = [(x / 10, 0.27, 90.0, 0.0) for x in range(-3, 4)]        # alongside, out of the way
    pts = [ahead_right, *left_wall]
    assert closing_in(pts, MovCmd.FORWARD, t) > 0 and closing_in(left_wall, MovCmd.FORWARD, t) == 0
    assert safe_instead(pts, MovCmd.FORWARD, t) == MovCmd.TURN_LEFT
    mirrored = [(bx, -by, -s, a) for bx, by, s, a in pts]
    assert safe_instead(mirrored, MovCmd.FORWARD, t) == MovCmd.TURN_RIGHT


def test_a_refused_walk_sidesteps_off_a_wall_alongside_when_turning_would_swing_into_it():
    """corridor_narrow seeds 18, 19: a few degrees off the corridor's axis, the right-hand wall 9 cm off the right
    flank and its echo 0.25 m ahead-right refuse FORWARD; either turn swings an end of the body into the wall,
    and backing off and walking on met the same wall again and again. The guard steps away from it instead."""
    from behaviours.np3_layers import closing_in, safe_instead
    t = Tuning()
    right_wall = [(x / 20, -0.17, -90.0, 0.0) for x in range(-4, 3)]
    left_wall = [(x / 20, 0.30, 90.0, 0.0) for x in range(-4, 5)]
    pts = [(0.25, -0.112, -15.0, 0.056), *right_wall, *left_wall]
    assert closing_in(pts, MovCmd.FORWARD, t) > 0
    assert closing_in(pts, MovCmd.TURN_LEFT, t) > 0 and closing_in(pts, MovCmd.TURN_RIGHT, t) > 0
    assert safe_instead(pts, MovCmd.FORWARD, t) == MovCmd.SIDESTEP_LEFT
    mirrored = [(bx, -by, -s, a) for bx, by, s, a in pts]
    assert safe_instead(mirrored, MovCmd.FORWARD, t) == MovCmd.SIDESTEP_RIGHT


def test_a_refused_command_hands_the_actuator_to_the_guard_reflex(spec):
    rig = np3(spec)
    rig.run(1.0)
    rig.inject(1.0, MCP, data("IRRC", quantizer(M.XmitDataIrrc, "center").raw(9.0), channel=1))   # 9 cm ahead
    rig.run(1.5)
    metrics = rig.node.debug_metrics()
    assert command_at(rig, 1.5) != MovCmd.FORWARD
    assert metrics["takeovers"].get("guard", 0) + metrics["takeovers"].get("avoid", 0) >= 1


def test_a_pit_found_has_the_task_layer_plan_again_at_once(spec):
    """seed 3.3.2: the map changed (a foot found no ground): a new plan within NP3_PLAN_CHANGED_S, not at the
    next periodic one (NP3_EXPLORE_PLAN_S), and the pit is on the map it is made on."""
    quiet, pit = np3(spec, task="explore"), np3(spec, task="explore")
    pit.inject(3.0, MCP, data("MMC", int(MmcError.NO_GROUND), STATUS, channel=4))
    for rig in (quiet, pit):
        rig.run(3.0 + T.NP3_PLAN_CHANGED_S + 0.2)
    assert [p.t for p in quiet.node.plans if p.t > 1.0] == []                # the periodic plan is 10 s away
    again = [p for p in pit.node.plans if p.t > 3.0]
    assert len(again) == 1 and again[0].t <= 3.0 + T.NP3_PLAN_CHANGED_S + 0.1
    assert pit.node.map.grid.barriers and set(pit.node.pit_cells) == pit.node.map.grid.barriers


def test_a_heading_goal_avoidance_kept_the_robot_from_is_not_chosen_again_there(spec):
    """A heading goal the robot came no nearer while a stronger layer took the actuator (the map shows the
    way open, the sensors do not): the next plan takes another heading (maze_far_room seed 9 stood 30 s)."""
    rig = np3(spec, task="explore")
    rig.run(2.0)
    node = rig.node
    first = node.heading_plan
    assert first is not None and node.blocked == deque()

    def replan() -> None:
        node.planned_at, node.next_plan = -math.inf, 0.0
        node.plan_goal(node.now)

    replan()                                   # not approached, but nothing fought it: nothing blocked
    second = node.heading_plan
    assert node.blocked == deque() and second is not None
    node.takeovers["avoid"] = node.takeovers.get("avoid", 0) + 1              # avoidance took over meanwhile
    replan()
    assert [b.heading for b in node.blocked] == [second.heading]
    turn = abs((node.heading_plan.heading - second.heading + math.pi) % (2 * math.pi) - math.pi)
    assert turn >= math.radians(T.NP3_EXPLORE_BLOCKED_DEG)


def test_a_pit_under_a_rear_foot_is_left_forwards_and_stays_on_the_map(spec):
    rig = np3(spec)
    rig.inject(1.0, MCP, data("MMC", int(MmcError.NO_GROUND), STATUS, channel=3))   # leg 3: rear left
    rig.run(1.05)
    x0 = rig.node.pose_at(None)[0]
    rig.run(1.5)
    assert command_at(rig, 1.5) == MovCmd.FORWARD and rig.node.takeovers.get("pit") == 1
    rig.run(1.0 + T.NP3_PIT_BACK_S + 0.5)
    assert command_at(rig, 1.0 + T.NP3_PIT_BACK_S + 0.5) == MovCmd.TURN_RIGHT      # away from the left side
    g = rig.node.map.grid
    assert g.barriers and all(g.centre(i, j)[0] < x0 - 0.05 for i, j in g.barriers)  # behind the body
    for i, j in g.barriers:
        g.mark_free(*g.centre(i, j), 0.3)                                           # walking there later ...
    assert all(g.state(i, j) == 2 for i, j in g.barriers)                           # ... does not clear it


def test_a_front_foot_over_a_pit_marks_a_stretch_of_its_edge_ahead_on_its_own_side(spec):
    """CHOICE (NP3.mark_pit, issue 17): one cell per NO_GROUND left a ring of pits as dots the sonar's free space
    lay between; the edge joins the map as a stretch across the way ahead, from the body's axis (the other front
    foot stands on ground) to beyond the foot, and NP3_PIT_EDGE_DEEP_M deep."""
    rig = np3(spec)
    rig.inject(1.0, MCP, data("MMC", int(MmcError.NO_GROUND), STATUS, channel=1))   # leg 1: front left
    rig.run(1.05)
    g = rig.node.map.grid
    pts = [g.centre(i, j) for i, j in g.barriers]
    fx, fy = DEFAULT_GEOMETRY.neutral_foot(1)
    assert all(x > fx - g.res and y > -g.res for x, y in pts)                     # ahead, not right of the axis
    ys, xs = [y for _x, y in pts], [x for x, _y in pts]
    assert max(ys) - min(ys) >= fy + T.NP3_PIT_EDGE_OUT_M - g.res                 # a stretch across the way
    assert max(xs) - min(xs) >= T.NP3_PIT_EDGE_DEEP_M - g.res                     # ... and deep


def test_pits_found_twice_have_the_task_layer_plan_a_route_out(spec, tmp_path):
    """seed 3.3.2, issue 17: the feet found a pit ahead and then, turned away, ahead again (NP3_RING_PITS): the
    task layer stops following open rays and plans a route over the map to beyond the pits found (kind "out"),
    within NP3_PLAN_CHANGED_S, the picture drawing it."""
    rig = np3(spec, task="explore")
    rig.inject(3.0, MCP, data("MMC", int(MmcError.NO_GROUND), STATUS, channel=1))   # front left: a pit ahead
    rig.inject(3.6, MCP, data("MMC", 0, STATUS, channel=0))                         # the foot back on ground
    rig.run(14.0)
    node = rig.node
    for _k in range(20):                        # what the sonar would have shown: free ground all round
        node.map.grid.mark_free(0.0, 0.0, 3.0)
    assert node.routes_out == 0 and all(p.kind != "out" for p in node.plans)
    assert abs(node.odo.th) >= math.radians(90)                                     # the reflex turned it away
    rig.inject(14.0, MCP, data("MMC", int(MmcError.NO_GROUND), STATUS, channel=4))  # front right: ahead again
    rig.run(14.0 + T.NP3_PLAN_CHANGED_S + 0.2)
    out = [p for p in node.plans if p.kind == "out"]
    assert out and out[0].t <= 14.0 + T.NP3_PLAN_CHANGED_S + 0.1 and node.routes_out >= 1
    ring = node.ring
    assert ring is not None and math.dist(out[0].route[-1], (ring.x, ring.y)) > ring.radius
    node.write_artifacts(tmp_path)
    colours = set(Image.open(tmp_path / "topomap.png").convert("RGB").getdata())
    assert {(150, 0, 0), (0, 170, 60)} <= colours        # the pits found, the route out followed


def test_the_reckoning_counts_no_motion_while_a_foot_has_no_ground(spec):
    """CHOICE (GaitReckoning.footless, issue 17): turning with a foot over a pit the body turned a fraction of what
    the gait commanded (pit_ring seed 4: 50 deg off in 3.5 s of a pit reflex's turn); while the MMC reports the
    foot without ground the reckoning counts no motion, and from its clear on it counts again."""
    rig = np3(spec)
    rig.inject(1.0, MCP, data("MMC", int(MmcError.NO_GROUND), STATUS, channel=1))
    rig.inject(2.5, MCP, data("MMC", 0, STATUS, channel=0))
    rig.run(1.1)
    held = rig.node.pose_at(None)
    rig.run(2.4)
    assert command_at(rig, 2.4) == MovCmd.BACKWARD and rig.node.pose_at(None) == held
    rig.run(3.4)
    assert rig.node.pose_at(None)[0] < held[0] - 0.02                                # backing off, counted


def test_dead_reckoning_knows_the_pose_at_an_earlier_time():
    """issue 17: a record's age asks for the pose the robot had when the value was measured."""
    odo = DeadReckoning(0.1, math.radians(25))
    odo.command(1.0, int(MovCmd.FORWARD))
    odo.command(2.0, int(MovCmd.TURN_LEFT))
    odo.command(3.8, int(MovCmd.STOP))
    odo.advance(4.0)
    assert odo.pose_at(0.5) == pytest.approx((0.0, 0.0, 0.0))
    assert odo.pose_at(1.5) == pytest.approx((0.05, 0.0, 0.0))
    x, y, th = odo.pose_at(2.9)                                   # half way through the turn
    assert (x, y, math.degrees(th)) == pytest.approx((0.1, 0.0, 22.5))
    assert odo.pose_at(5.0) == odo.pose and math.degrees(odo.pose[2]) == pytest.approx(45.0)


def test_the_gait_models_dead_reckoning_knows_the_pose_at_an_earlier_time():
    """issue 17 + s9-light: the reckoning through the gait model answers pose_at(t) with the pose it had at t,
    also mid-turn and inside a re-phase pause (the command's own leg would hold the pose it started from)."""
    plan = [(0.0, MovCmd.FORWARD), (2.0, MovCmd.TURN_LEFT), (3.6, MovCmd.FORWARD), (4.4, MovCmd.STOP)]
    odo = GaitReckoning(DEFAULT_GEOMETRY, T.NP3_DR_GRIP, T.NP3_DR_TURN_GRIP, T.MMC_CONTROL_S)
    twin = GaitReckoning(DEFAULT_GEOMETRY, T.NP3_DR_GRIP, T.NP3_DR_TURN_GRIP, T.MMC_CONTROL_S)
    for at, cmd in plan:
        odo.command(at, int(cmd))
    odo.advance(5.0)
    queue = list(plan)
    for t in (1.505, 2.505, 3.005, 3.905, 4.605):                 # between steps; the twin walked only up to t
        while queue and queue[0][0] <= t:
            at, cmd = queue.pop(0)
            twin.command(at, int(cmd))
        twin.advance(t)
        assert odo.pose_at(t) == pytest.approx(twin.pose, abs=1e-9)
    assert math.degrees(odo.pose_at(3.005)[2]) > 5.0 and odo.pose_at(3.005) != odo.pose_at(2.005)
    first, last = odo.legs[0], odo.legs[-1]
    assert last.t - odo.legs[1].t <= T.NP3_POSE_HISTORY_S < last.t - first.t     # the history is kept, no more
    assert odo.pose_at(0.0) == (first.x, first.y, first.th)                        # before it: its start


def test_a_heading_correction_turns_the_pose_history_echoes_and_pings_with_the_pose(spec):
    """3.3.2 + issue 17: the map turns the heading by 10 deg while the robot turns on the spot; a ping's pose
    from before, the echo records and the pings' free space turn with it about the robot, so that an echo
    placed from the corrected pose of its ping lies where the turned memory has it."""
    rig = np3(spec, task="idle")
    rig.run(1.0)
    node = rig.node
    odo = DeadReckoning(0.1, math.radians(22.5))
    odo.command(0.0, int(MovCmd.FORWARD))
    odo.command(0.5, int(MovCmd.TURN_LEFT))                       # at (0.05, 0): turns 22.5 deg/s from here
    node.odo = odo
    rig.run(2.0)
    assert odo.cmd == int(MovCmd.TURN_LEFT)                       # the idle task sent nothing meanwhile
    ping = node.pose_at(0.3)
    echo = Echo(0.3, 0.5, 0.4, -20.0, 0.05, sonar=True)
    node.echoes.append(echo)
    node.pings.append(Ping(0.3, 0.03, 0.0, 0.3, 1.0))
    here = node.pose_at(None)
    turn = math.radians(10)
    node.correct_heading(turn)

    def turned(px, py):
        dx, dy = px - here[0], py - here[1]
        return (here[0] + dx * math.cos(turn) - dy * math.sin(turn), here[1] + dx * math.sin(turn) + dy * math.cos(turn))
    assert node.pose_at(None) == pytest.approx((here[0], here[1], here[2] + turn))
    assert node.pose_at(0.3) == pytest.approx((*turned(ping[0], ping[1]), ping[2] + turn))
    assert node.pose_at(1.0)[2] == pytest.approx(math.radians(22.5 / 2) + turn)   # the turn's leg, corrected
    (e,), (p,) = list(node.echoes), list(node.pings)
    assert isinstance(e, Echo) and (e.x, e.y) == pytest.approx(turned(0.5, 0.4))
    assert (e.t, e.seen_deg, e.arc_m, e.sonar) == (0.3, -20.0, 0.05, True)    # body-relative: unchanged
    assert isinstance(p, Ping) and (p.x, p.y, p.bearing) == pytest.approx((*turned(0.03, 0.0), 0.3 + turn))
    assert node.heading_fixed == pytest.approx(turn)


def test_a_sonar_echo_is_placed_at_the_heading_of_its_ping(spec):
    """issue 17: while turning, an echo that arrives 1.5 s after its ping lies where the ping saw it."""
    metres = quantizer(M.XmitDataUsrc, "distance")
    rig = np3(spec, task="idle")
    rig.run(1.0)
    odo = DeadReckoning(0.1, math.radians(22.5))
    odo.command(0.0, int(MovCmd.TURN_LEFT))
    odo.command(2.0, int(MovCmd.STOP))                             # 45 deg at t = 2 s
    rig.node.odo = odo
    rig.inject(2.5, MCP, data("USRC", metres.raw(1.0), VALUE, channel=0, age_s=1.5))   # pinged at 1.0 s: 22.5 deg
    rig.run(2.6)
    pts = [e for e in rig.node.echoes if e.sonar]
    assert len(pts) == T.NP3_SONAR_CONE_POINTS
    mid = pts[len(pts) // 2]
    d = metres.phys(metres.raw(1.0))
    assert (mid.x, mid.y) == pytest.approx((d * math.cos(math.radians(22.5)), d * math.sin(math.radians(22.5))),
                                           abs=0.02)


def test_a_later_ping_clears_the_cone_points_it_shows_free_and_keeps_the_wall(spec):
    """issue 17: in a corridor (walls 0.25 m either side) a ping 15 deg off the axis puts the inner edge of its
    cone into the legs' way; a ping from 0.3 m further on, whose cone passes over that spot, clears it; the
    wall's points and an IR point stay."""
    rig = np3(spec, task="idle")
    rig.run(1.0)
    node = rig.node
    node.echoes.append(Echo(1.0, 0.45, 0.10, 0.0, 0.0))           # an IR point: the sonar never clears it
    node.sonar_memory(Ping(1.0, 0.0, 0.0, math.radians(15), 0.25 / math.sin(math.radians(22.5))), 15.0)
    band = Tuning().body_half_width_m + Tuning().guard_margin_m   # the guard's band beside the body
    first = [e for e in node.echoes if e.sonar]
    assert min(e.y for e in first) < band
    node.sonar_memory(Ping(1.2, 0.3, 0.0, math.radians(15), 0.25 / math.sin(math.radians(22.5))), 15.0)
    kept = [e for e in first if e in node.echoes]
    assert len(kept) >= 2 and min(e.y for e in kept) > band
    assert max(e.y for e in kept) == pytest.approx(0.25)           # the wall itself stays
    assert Echo(1.0, 0.45, 0.10, 0.0, 0.0) in node.echoes


def test_a_wall_alongside_seen_off_the_axis_is_no_obstacle_ahead(spec):
    """issue 17 (wall_follow): the wall 0.35 m to the right, a ping 15 deg right of the axis meets it at the cone's
    outer edge; the cone's inner points lie in the corridor ahead, but the reflector may be anywhere up to the
    outer edge, so none is surely in the way (they had made a corner out of nothing). Looking straight at a
    wall 0.4 m ahead, every point of the cone is."""
    rig = np3(spec, task="idle")
    rig.run(1.0)
    node = rig.node
    edge = math.radians(15 + T.NP3_SONAR_BEAM_DEG / 2)
    node.sonar_memory(Ping(1.0, 0.0, 0.0, math.radians(-15), 0.35 / math.sin(edge)), -15.0)
    pts = body_frame(tuple(e.point() for e in node.echoes), (0.0, 0.0, 0.0))
    assert len(pts) == T.NP3_SONAR_CONE_POINTS and min(abs(p[1]) for p in pts) < 0.15    # inner edge in the way
    assert clear_ahead(pts, T.NP3_WALL_TARGET_M - T.NP3_WALL_DEADBAND_M) == math.inf
    before = len(node.echoes)
    node.pings.clear()        # a case of its own: a wall 0.4 m ahead would have answered the first ping at its edge
    node.sonar_memory(Ping(1.1, 0.0, 0.0, 0.0, 0.4), 0.0)
    ahead = body_frame(tuple(e.point() for e in list(node.echoes)[before:]), (0.0, 0.0, 0.0))
    assert len(ahead) == T.NP3_SONAR_CONE_POINTS
    assert all(clear_ahead([p], T.NP3_AVOID_HALF_WIDTH_M) == pytest.approx(p[0]) for p in ahead)


def test_the_ping_straight_ahead_clears_the_inner_edge_of_the_ping_15_deg_off(spec):
    """issue 17 (corridor_narrow seeds 3, 4): walls 0.25 m either side, the ping 15 deg left puts the inner edge of
    its cone 0.085 m off the axis 0.65 m ahead; the ping straight ahead, whose beam shares that edge and meets the
    walls only 1.9 m on, shows it free. With a cone narrower than the beam it stayed in the legs' way."""
    rig = np3(spec, task="idle")
    rig.run(1.0)
    node = rig.node
    edge = math.radians(T.NP3_SONAR_BEAM_DEG / 2)
    node.sonar_memory(Ping(1.0, 0.0, 0.0, math.radians(15), 0.25 / math.sin(math.radians(15) + edge)), 15.0)
    band = Tuning().body_half_width_m + Tuning().guard_margin_m
    assert min(abs(e.y) for e in node.echoes if e.sonar) < band
    node.sonar_memory(Ping(1.6, 0.0, 0.0, 0.0, 0.25 / math.sin(edge)), 0.0)
    left = [e for e in node.echoes if e.sonar]
    assert left and min(abs(e.y) for e in left) > band
    assert max(e.y for e in left) == pytest.approx(0.25, abs=0.01)     # the wall's point stays


def test_the_reckoning_stops_where_the_mmc_stopped_at_a_pit(spec):
    """seed 1.2.2 + issue 17 (s10-heading): the MMC stops at once when a foot finds no ground; the NP3 learns it
    from the STATUS record. Its reckoning counts no walking from then on (the legs made none), and the command
    it wants next goes out to the MMC even when it is the one sent before (a rear foot's pit: walk on forwards)."""
    rig = np3(spec)
    rig.run(1.0)
    walked = rig.node.pose_at(None)[0]
    assert walked > 0.02 and command_at(rig, 1.0) == MovCmd.FORWARD
    rig.inject(1.0, MCP, data("MMC", int(MmcError.NO_GROUND), STATUS, channel=3))   # leg 3: rear left
    rig.run(1.5)
    after = [t for t, m in moves(rig) if t >= 1.0]
    assert after and command_at(rig, 1.5) == MovCmd.FORWARD           # sent again: the MMC had stopped
    assert rig.node.odo.pose_at(after[0] - 0.01)[0] == pytest.approx(rig.node.odo.pose_at(1.0)[0], abs=1e-3)


def test_a_lost_leg_walks_the_reckonings_gait_on_five_legs_with_the_waves_grip(spec):
    """seed 6.3 + issue 17: a leg out of order (the MMC's STATUS) makes the MMC walk the five-legged wave; the
    NP3's copy of the gait drops the leg too, so its turns and strides follow the wave's, at the wave's grip."""
    rig = np3(spec)
    rig.run(0.5)
    odo = rig.node.odo
    assert odo.turn_grip == T.NP3_DR_TURN_GRIP["TRIPOD"]
    rig.inject(0.5, MCP, data("MMC", int(MmcError.LCP_OUT_OF_ORDER), STATUS, channel=2))
    rig.run(4.0)
    assert odo.gait.lost == {2} and 2 not in odo.gait.legs
    assert odo.turn_grip == T.NP3_DR_TURN_GRIP["WAVE"]


def test_the_reckonings_turn_grip_is_the_running_gaits():
    """issue 17: measured per gait (tuning.NP3_DR_TURN_GRIP): the same turn commanded in the ripple counts the
    ripple's share of the model's turn, in the tripod the tripod's."""
    turned = {}
    for gait in ("TRIPOD", "RIPPLE"):
        odo = GaitReckoning(DEFAULT_GEOMETRY, T.NP3_DR_GRIP, T.NP3_DR_TURN_GRIP, T.MMC_CONTROL_S)
        bare = GaitReckoning(DEFAULT_GEOMETRY, T.NP3_DR_GRIP, dict.fromkeys(T.NP3_DR_TURN_GRIP, 1.0), T.MMC_CONTROL_S)
        for r in (odo, bare):
            r.command(0.0, int(MovCmd[gait]))
            r.command(0.0, int(MovCmd.TURN_LEFT))
            r.advance(4.0)
        assert bare.th > math.radians(30)
        turned[gait] = odo.th / bare.th
    assert turned == pytest.approx({g: T.NP3_DR_TURN_GRIP[g] for g in turned}, abs=1e-9)


def test_a_refused_step_away_from_a_fresh_touch_never_steps_or_turns_into_it():
    """corridor_narrow seed 20: the right feeler touched the wall alongside, the contact reflex's SIDESTEP_LEFT
    was refused for a remembered echo off the left rear (placed by a heading 12 deg off), and the guard's
    first alternative, SIDESTEP_RIGHT, walked the body into the wall it had just touched."""
    from behaviours.np3_layers import closing_in, safe_instead
    t = Tuning()
    left_rear = [(-0.152, 0.202, 90.0, 0.0)]
    assert closing_in(left_rear, MovCmd.SIDESTEP_LEFT, t) > 0
    assert safe_instead(left_rear, MovCmd.SIDESTEP_LEFT, t) == MovCmd.SIDESTEP_RIGHT      # no touch known
    instead = safe_instead(left_rear, MovCmd.SIDESTEP_LEFT, t, touched=-1.0)
    assert instead not in (MovCmd.SIDESTEP_RIGHT, MovCmd.TURN_RIGHT) and closing_in(left_rear, instead, t) == 0
    mirrored = [(-0.152, -0.202, -90.0, 0.0)]
    assert safe_instead(mirrored, MovCmd.SIDESTEP_RIGHT, t, touched=1.0) not in (MovCmd.SIDESTEP_LEFT,
                                                                               MovCmd.TURN_LEFT)
