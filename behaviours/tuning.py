"""Behaviour tuning: every number the nodes' firmware chooses for itself, in one place.

None of these is a protocol rule: bus timing, retries, timeouts, POST rules
and set-point refresh come from the spec (arachnae_proto and
behaviours.netconfig). These are control periods, thresholds and rate limits
the seed leaves to the implementer (CHOICE); changing one changes how the
robot behaves, never what goes on the wire's format.
"""
from __future__ import annotations

from behaviours.geometry import BodyPoint

# --- MMC (seed 3.2.4): gait clock, leg polling, errors
MMC_CONTROL_S = 0.02          # gait generator period
MMC_POLL_S = 0.04             # one LEG_POLL every 40 ms, legs in turn: each leg every 240 ms (a pit within ~0.5 s);
                              # a poll and its report take ~12 ms of the 19200-baud leg bus
MMC_LEG_TIMEOUTS = 4          # this many LEG_POLLs in a row unanswered (each with the bus's retry, asked again at
                              # once): LCP out of order, about 0.2 s after it fell silent
MMC_HIGH_STEP_S = 6.0         # after a blocked leg every swing lifts to the step limit this long (obstacle underfoot)
MMC_OVERTEMP_SCALE = 0.5      # a leg reports servo over-temperature: the whole gait runs at half speed
MMC_LOST_LEG_LIFT_M = 0.06    # a lost leg whose LCP still answers is held this high ...
MMC_LOST_LEG_TUCK_M = 0.03    # ... and this much closer to the body, out of the way

# --- gait generator (behaviours.gait, runs in the MMC)
GAIT_OVERRUN = 0.15           # a stance foot may go this fraction of a stroke past its rear end before the body waits
GAIT_MIN_SWING = 0.5          # a swing never lasts less than half its normal time (late lift-off after a re-phase),
                              # and is re-aimed at a new direction's touchdown only with at least that much time left
GAIT_REPHASE_STEPS = 48       # candidate phases tried when fitting a new gait to where the feet are
GAIT_OVERRUN_WEIGHT = 100.0   # cost of an overrun (per stroke squared) against a merely short or long step
GAIT_PAUSE_WEIGHT = 1e4       # cost of each second the body would pause for a re-phased foot to lift (minimax first)
GAIT_FIVE_LEG_STROKE = 0.5    # five legs: half the stroke, so four feet always hold the body inside their polygon
GAIT_FIVE_LEG_SPREAD = 0.5    # five legs: the two feet on the lost leg's side stand at +-this x the front hip's x

# --- LCP (seed 3.2.10, 6.1)
LCP_CONTROL_S = 0.1           # 10 Hz set points per joint, each with the speed to arrive in one period
LCP_SWING_EDGE = 0.25         # a swing lifts straight up in its first quarter, lowers straight down in its last
LCP_BLOCK_CURRENT_A = 1.0     # above free-running servo current (0.35 A), below stall (1.8 A): leg blocked
LCP_SETTLE_S = 0.3            # a carrying foot without sole contact this long (after touchdown): no ground (pit)
LCP_SET_DOWN_S = 0.15         # a stance target reaching a foot still in the air: it is set down within this time
LCP_GROUND_SEARCH_M = 0.03    # CHOICE: a carrying foot without contact reaches this far down before "no ground"
LCP_GROUND_SEARCH_M_S = 0.1   # CHOICE: how fast it reaches down (m/s)
LCP_GROUND_REACHED_M = 0.01  # a foot without contact is over a pit only if its JACs put it this low (else: on a face)
LCP_NO_GROUND_Z_M = 0.03      # seed 1.2.2: over a pit the foot hovers this high and carries no weight
LCP_MIN_SPEED_DEG_S = 30.0    # slowest commanded joint speed: a joint catches up after a lost set point
LCP_SPEED_MARGIN = 2.0        # commanded speed = this x the speed needed to arrive within one period
LCP_RETRACT = 0.3             # seed 6.1: a blocked foot goes back this fraction towards its segment start
LCP_RETRY_MIN_S = 0.2         # shortest retried swing after a block
LCP_RETRY_GRACE_S = 0.15      # stall current this soon after the retract began is still the first block
LCP_STALL_HOLD_S = 0.3        # a leg stalled this long outside a swing stops pushing (servo protection, issue 18);
                              # 3 polls: long enough to pass a foot's moment of catching as it is set down
LCP_STALL_GAP_S = 0.35        # ... a stall with no report of stall current for longer (a round of 3 JAC polls) is over
LCP_RETRY_CLEARANCE_M = 0.01  # retried swing lifts this much above the step limit
LCP_HIGH_STEPS = 3            # after a block the leg's next swings step that high too (the obstacle is still there)
LCP_JAC_TIMEOUTS = 4          # this many JOINT_POLLs in a row unanswered (each with the bus's retry, asked again at
                              # the next period): JAC fault

# --- JAC (seed 3.2.18)
JAC_CONTROL_S = 0.01          # the servo's position loop runs at 100 Hz on the JAC's timer
JAC_KP = 40.0                 # 1/s: speed command per radian of position error (time constant 25 ms)
JAC_DEADBAND_RAD = 1e-3       # closer than this: no drive (below the set point's 0.1 degree resolution)
JAC_STALL_CURRENT_A = 1.5     # motor current flagged OVERCURRENT
JAC_STALL_MIN_DRIVE = 0.2     # rad/s: commanded at least this ...
JAC_STALL_SPEED = 0.02        # ... while the tacho reads less than this ...
JAC_STALL_S = 0.05            # ... for this long: STALLED (seed 6.1)
JAC_AT_TARGET_RAD = 2e-3      # within this of the set point and at rest: AT_TARGET
JAC_OVERTEMP_C = 70.0         # winding temperature flagged OVERTEMP (hobby servo motors are rated ~80 C) ...
JAC_OVERTEMP_HYST_C = 5.0     # ... until it has cooled this much below the limit
JAC_WATCHDOG_S = 1.0          # no set point this long (5 refresh periods): the LCP is gone, the servo goes limp

# --- NP3 (seed 3.2.3, 3.3.2, 5.1-5.2, 6, docs/decisions.md D8): the subsumption network's numbers, all CHOICE
NP3_PERIOD_S = 0.1            # the network is evaluated every 100 ms (5.2: reactions well within 1 s)
NP3_START_LOOK_S = 1.0        # after INIT no step until the IR and whiskers reported (the SPU polls them first, see
                              # SPU_FIRST_POLL), at most this long
NP3_REFLEX_HOLD_S = 0.5       # suppressor time constants: reflexes ...
NP3_AVOID_HOLD_S = 0.3        # ... and obstacle avoidance keep the lower layers cut this long
NP3_CONTACT_BACK_S = 1.6      # contact (whisker, IR very close) with the surface ahead: back off at least one
                              # tripod cycle (longer if the body's corners would sweep into it turning) ...
NP3_CONTACT_AHEAD_DEG = 60.0  # ... "ahead": its normal (IR line fit) within this of the heading ...
NP3_CONTACT_CLEAR_DEG = 20.0  # ... then turn until the surface's normal is this far behind the side (walk away),
NP3_CONTACT_MIN_TURN_DEG = 30.0   # ... at least this far;
NP3_CONTACT_WHISKER_NORMAL_DEG = 60.0  # a whisker alone (IR beams clear): the surface taken to face this far aside
                              # (a touch of a feeler's lane wire too: its echoes keep the turn off the post, D18)
NP3_CONTACT_CORNER_M = 0.01   # the IR centre point this far behind the line through the side points: a corner;
NP3_CONTACT_CORNER_NORMAL_DEG = 45.0  # ... the side beams alone see a corner: its walls taken to face this far aside
NP3_CONTACT_NEAR_M = 0.1      # ... a remembered echo beside the body this close to it: a wall alongside
NP3_CONTACT_WALL_BEYOND_M = 0.12  # a single whisker, IR clear, a sonar echo beside the body at most this further
NP3_CONTACT_WALL_ALONG_M = 0.3    # ... out than the outer wire's tip and this near it along the axis: a wall
                              # alongside touched that wire's tip (D18): one point there, none in the lane, and ...
NP3_CONTACT_ALONGSIDE_S = 0.6 # ... the escape a sidestep away this long (5 cm: the tip off the wall), no 60 deg
                              # guess's turn (from a wall of a 0.5 m corridor it faced the body at the other one);
NP3_CONTACT_ALONGSIDE_MIN_DEG = 3.0  # ... then a turn parallel to the wall if it closes in ahead by this much or more
NP3_CONTACT_WALL_REACH_M = 0.35      # ... (the line through the remembered echoes this near the axis on that side)
NP3_IR_CONTACT_M = 0.03       # an IR echo this close counts as contact
NP3_AVOID_CENTRE_M = 0.08     # avoidance: the centre beam sees something this close ...
NP3_AVOID_SIDE_M = 0.06       # ... or a side beam this close -> turn away
NP3_AVOID_SONAR_M = 0.35      # ... or the sonar, looking ahead (+-15 deg), this close
NP3_AVOID_TURN_S = 0.8        # one half cycle of turning per avoidance
NP3_AVOID_KEEP_SIDE_S = 3.0   # ... the way it turned kept while the next comes within this (no dithering at a wall)
NP3_AVOID_SQUARE_DEG = 10.0   # ... when the surface in the way faces the body within this of the heading (square
                              # on); beyond it, away from the side it faces the body from
NP3_SONAR_AHEAD_DEG = 15      # a sonar reading this close to the body axis counts as "ahead"
NP3_SONAR_FRESH_S = 1.5       # ... while it is this recent
NP3_PIT_BACK_S = 2.4          # pit (MMC NO_GROUND): back off ...
NP3_PIT_TURN_S = 4.8          # ... then turn about 120 degrees
NP3_TILT_LIMIT_DEG = 25.0     # dangerous inclination (ISC measures -60..60 deg, 3.2.14)
NP3_TILT_BACK_S = 3.2         # too steep: back off downhill ...
NP3_TILT_TURN_S = 6.4         # ... and turn around (about 160 degrees)
NP3_LEG_BLOCKED_HOLD_S = 0.8  # blocked leg (6.1): hold still while the LCP retracts and re-plans
NP3_LEG_BLOCKED_SIDE_S = 0.8  # ... then sidestep this long away from the blocked leg's side
NP3_AVOID_ECHO_M = 0.35       # avoidance: a remembered echo this far ahead of the body centre ...
NP3_AVOID_HALF_WIDTH_M = 0.16 # ... within this of the body axis (body 0.08 m, the legs' tips 0.2 m: a foot that
                              # meets something is a blocked leg, seed 6.1, and a corridor 0.5 m wide stays passable)
NP3_GUARD_MARGIN_M = 0.04    # motion check (5.1.2): no command may bring the body outline closer than this ...
NP3_GUARD_HORIZON_S = 1.0     # ... to a remembered echo within this long (the gait takes a half cycle to stop);
NP3_GUARD_HOLD_S = 0.3        # ... a refused command is replaced by a safe one this long
NP3_TOUCH_FRESH_S = 2.0       # ... and for this long after one feeler touched, nothing it gives instead moves towards
                              # that side (CHOICE: a contact manoeuvre's sidestep and turn take 0.6-1.5 s)
NP3_PINNED_PROGRESS_M = 0.2   # pinned body (issue 17): over this much forward walking (dead reckoning) ...
NP3_PINNED_CHANGE = 0.25      # ... a sonar range that changed by less than this share of it shows no motion along
                              # its beam (noise 2 cm: a difference has 2.8 cm sigma; a range ahead changes by all 0.2 m) ...
NP3_PINNED_ANGLES = 3         # ... and with this many scan angles, on both sides of the axis, all showing none
NP3_PINNED_RANGE_M = (0.3, 8.0)   # ... (readings within this range only: the sonar's blind zone and no echo say nothing)
NP3_PINNED_WINDOW_S = 4.0     # ... each angle's last comparison counting this long (the sweep's 0 and +-15 deg come
                              # round every 3.6 s): the body is held now, not at some time before
NP3_PINNED_REF_S = 8.0        # ... against a ping at that angle at most this old (the heading has drifted since)
NP3_PINNED_BESIDE_M = 0.6     # ... not while a remembered echo lies beside the body within this (walls along the way)
NP3_SOUND_MIN_DEG = 10        # sound straight ahead within this: no turn needed
NP3_EXPLORE_PLAN_S = 10.0     # explore: a new goal every 10 s (5.2: navigation 10..30 s) or when reached:
NP3_EXPLORE_HEADINGS = 16     # ... the best of this many headings round the robot, scored on the map by
NP3_EXPLORE_REACH_M = 3.0     # ... the cells not yet passed along the ray, up to this far, before an obstacle;
NP3_EXPLORE_MARGIN_M = 0.5    # ... the goal stays this far short of the obstacle
NP3_EXPLORE_GOAL_M = 2.0      # ... and at most this far away
NP3_EXPLORE_SEEN_M = 0.5      # ... cells within this of the path count as passed
NP3_EXPLORE_BLOCKED_M = 0.6   # a heading goal not approached while avoidance took over: that heading is not chosen
NP3_EXPLORE_BLOCKED_DEG = 30.0  # ... again within this of where it failed, this close to it (a few kept)
NP3_EXPLORE_BLOCKED_KEEP = 6
NP3_EXPLORE_WANDER_S = 12.0   # explore without a goal: a new heading every 12 s ...
NP3_EXPLORE_TURN_S = 2.4      # ... turning this long
NP3_GOAL_REACHED_M = 0.4      # a goal this close (dead reckoning) is reached
NP3_PLAN_MIN_PATH_M = 1.5    # explore: a route over the map to the nearest frontier at least this far (3.3.2) ...
NP3_PLAN_MIN_FRONTIER = 20    # ... of at least this many cells (smaller ones are gaps between sonar beams)
NP3_PLAN_EXCLUDE_M = 0.5      # ... committed to until no frontier cell is left this near it (explored) or no
                              # route leads there; frontier cells this near a frontier given up on do not count
NP3_PLAN_PROGRESS_M = 0.3     # ... and given up when its route has not shortened by this much ...
NP3_PLAN_PATIENCE_S = 40.0    # ... for this long (4 replans: walked round walls at 0.09 m/s, a route shortens faster)
NP3_PLAN_CHANGED_S = 1.0      # ... and planned again this soon after a pit or refused slope joins the map
NP3_PIT_EDGE_OUT_M = 0.3      # a front or rear foot's NO_GROUND marks the pit's edge from the body's axis to this far
                              # beyond the foot (issue 17, pit_ring) ...
NP3_PIT_EDGE_ALONG_M = 0.15   # ... a middle foot's this far either way along the body ...
NP3_PIT_EDGE_DEEP_M = 0.3     # ... this deep: a hole the body cannot step over (the step limit is centimetres)
NP3_RING_PITS = 2             # hemmed in by pits (3.3.2): the feet found this many pit edges (one per NO_GROUND) ...
NP3_RING_NEAR_M = 3.0         # ... plans a way out to this far beyond the farthest pit cell found this near the
NP3_RING_OUT_M = 0.5          # ... middle of its path,
NP3_RING_WARY_M = 0.6         # ... wary of ground this near a pit cell found (a pit's edge runs on) ...
NP3_RING_WARY_COST = 4.0      # ... which costs up to this many times its length more
NP3_SEEK_FRONTIER_WEIGHT_M = 0.1  # seeking a light no sample shows: a frontier cell is worth this much path (the
                              # widest opening onto the unknown, where a lamp behind a wall is, before the nearest)
NP3_HEADING_TOL_DEG = 20.0    # steering: turn on the spot while the goal is further off the axis than this
NP3_LIGHT_SAMPLES = 8         # light gradient: plane fitted through this many (pose, log lux) samples
NP3_LIGHT_MIN_SPREAD_M = 0.15 # ... spread at least this far in both directions for a first fit (one L); later
                              # fits lean on the last one with the weight of samples this far apart (ridge)
NP3_LIGHT_PROBE_S = 6.0       # without a gradient: walk this long, then turn a quarter
NP3_LIGHT_WEAVE_DEG = 20.0    # with a gradient: weave this far either side of it ...
NP3_LIGHT_WEAVE_S = 8.0       # ... changing side this often (the fit needs samples spread across the way)
NP3_LIGHT_CLEAR_M = 0.6       # ... on the heading nearest the target with this much clear in the echo memory,
NP3_LIGHT_DETOUR_STEP_DEG = 20.0  # ... tried in steps this wide either side (bug-style round an obstacle)
NP3_LIGHT_DETOUR_HOLD_S = 10.0   # ... keeping a detour's side this long after the last blocked heading
NP3_MAPPED_NEAR_M = 1.0       # ... the map's occupied cells this near the robot count as obstacles too (3.3.2;
                              # beyond light_clear_m plus the body's half length: what a detour heading can meet)
NP3_LIGHT_FLAT_STEPS = 5      # seeking light: samples spanning fewer than this many LSC steps (1/64 decade, 3.6 %
                              # each, from the spec) show no light to climb (a lamp shaded by a wall): explore the map
                              # instead (3.3.2) until a sample is that much brighter. Measured, issue 17: at 5 lx
                              # ambient a flat reading's noise spans 1-3 steps (1 step flipped "dark" on and off);
                              # the lamp seen past a wall's end reads 6x-16x the ambient (40-60 steps)
NP3_MAP_SIZE_M = 12.0         # topological map: a square this wide around the start ...
NP3_MAP_CELL_M = 0.1          # ... in cells this wide
NP3_SONAR_BEAM_DEG = 15.0     # width a sonar echo is spread over on the map (40 kHz transducer cone)
NP3_DR_FOOTLESS_GRIP = 0.0     # dead reckoning while the MMC reports a foot without ground: none of the motion counts
                              # (CHOICE, issue 17: turning with a foot over a pit the body turned a fraction of the
                              # gait's turn; worst heading error, pit_ring seeds 1-5 at 180 s, bench/dr_heading.py:
                              # 19-179 deg, mean 76, counting it all; 19-48, mean 32, counting none)
NP3_DR_SPEED_M_S = 0.09       # dead reckoning: forward / backward speed (bench: the gait's nominal 0.1 m/s
NP3_DR_SIDE_M_S = 0.083       # ... loses ~10 % re-phasing), sidestep speed,
NP3_DR_TURN_DEG_S = 22.5      # ... and turn rate on the spot (nominal 25 deg/s), all measured in sim2d
NP3_POSE_HISTORY_S = 3.0      # dead reckoning: commands kept this long, for the pose at a record's age (issue 17;
                              # the age field reaches 2.55 s)
NP3_DR_GRIP = 0.955           # dead reckoning through the gait model (np3.GaitReckoning): the share of the stance feet's
                              # ... motion the body makes (bare gait in sim2d: 10 s forward 0.952 of 1.0 m, 5 s sidestep
                              # ... 0.478 of 0.5 m), and of their turn: through the LCPs' straight stance segments the
NP3_DR_TURN_GRIP = {"TRIPOD": 0.95, "RIPPLE": 1.0, "WAVE": 1.0}   # ... feet slip more, per gait (issue 17,
                              # s10-heading, bench/dr_heading.py: the body's turn per turn episode (to 1 s after it)
                              # against the NP3's copy at grip 1; tripod over 15 task runs (corridor_narrow 1-5,
                              # seek_light 1-5, light_behind_wall 1-4) 23532 of 24718 deg = 0.952, per run 0.85-0.97
                              # (turns beside walls slip more); against the MMC's own gait 0.940 (the copy turns 1 %
                              # less: the MOVE's way, stops it learns late); operator probes in an empty room 0.93-0.94
                              # of the MMC's; ripple 0.97-1.01, wave 0.95-1.06 (probes): 0.91 / 0.955 mixed gaits
NP3_MATCH_SEARCH_DEG = 10     # heading from the map (3.3.2, the tasks that plan on it): an echo of a mapped surface
NP3_MATCH_TOL_M = 0.08        # ... votes for the heading offset (searched this far either side) under which the map
NP3_MATCH_WIDTH_DEG = 6       # ... predicts its range within this (2 cm sonar noise, 10 cm cells), if the offsets
NP3_MATCH_RANGE_M = (0.5, 5.0)  # ... that fit span at most this; echoes within this range of the robot vote;
NP3_MATCH_VOTES = 5           # ... every this many votes the heading moves by
NP3_MATCH_GAIN = 0.7          # ... this share of their median,
NP3_MATCH_STEP_DEG = 5.0      # ... at most this much at once
NP3_ECHO_KEEP_S = 10.0        # local memory: sonar / IR / whisker echoes at the dead-reckoned pose kept this long
NP3_ECHO_NEAR_M = 1.5         # ... sonar echoes nearer than this only (the map keeps the rest), each as
NP3_SONAR_CONE_POINTS = 5     # ... this many points across the beam (the reflector is somewhere on that arc);
NP3_SONAR_CARVE_S = 5.0       # ... a ping of the last 5 s clears the points of others inside its cone (the whole beam)
NP3_SONAR_CARVE_TOL_M = 0.06  # ... and nearer than its own echo by this much (noise 2 cm, one step 4 cm; issue 17)
NP3_BODY_FRONT_M = 0.15       # sensor mounts as the NP3 knows them: IR and whiskers at the body's front (CHOICE),
NP3_IR_BEAM_DEG = 15.0        # ... the IR side beams at +-15 deg (seed 3.2.13),
NP3_WHISKER_ARMS = (          # ... and the left feeler's wires (the right one's mirrored), from its root at the
    (BodyPoint(0.15, 0.08), BodyPoint(0.2406, 0.1223)),                  # front corner: 10 cm 25 deg outward,
    (BodyPoint(0.15, 0.08), BodyPoint(0.2016, 0.1771)),                  # ... 11 cm 62 deg outward (beside) ...
    (BodyPoint(0.15, 0.08), BodyPoint(0.195, 0.08), BodyPoint(0.195, 0.015)),  # ... and bent across the lane ahead
)                             # (seed 1.2.2, CHOICE: sim2d.robot_params.whisker_arms, docs/decisions.md D18)
NP3_WALL_TARGET_M = 0.30      # wall following: body centre to the right-hand wall (feet reach 0.2 m sideways) ...
NP3_WALL_DEADBAND_M = 0.05    # ... corrected by a sidestep when off by more than this
NP3_WALL_CORNER_M = 0.45      # ... a wall ahead this close (centre) is a corner: turn left
NP3_WALL_ALIGN_DEG = 6.0      # ... the wall's fitted direction this far off the heading: turn to align
NP3_WALL_LOST_S = 8.0         # ... no wall beside for this long: turn right to find it again

# --- SPU (seed 3.2.5): polling order, status checks, alarms and forwarding rate limits to the NP3 (all CHOICE)
SPU_CYCLE = ("IRRC", "USRC", "IRRC", "LSC", "IRRC", "USRC", "IRRC", "ISC",   # IR every 2nd poll (5.2), the
             "IRRC", "USRC", "IRRC", "TSC", "IRRC", "USRC", "IRRC", "PSC")   # sonar every 4th: one angle of its scan
SPU_SCAN_AHEAD_DEG = (0, 15, -30, -15, 0, 15, 30, -15)   # the sonar scan the SPU drives (HEAD_SET_ABS + DO_MEASURE,
                              # 3.2.11; issue 17): a sweep ahead of the heading, where the robot walks and turns, the
                              # sides in turn: each +-15 deg angle every 4th (a back-and-forth sweep brought one side's
                              # twice in a row, then none for 3.6 s: a cone point of a corridor's wall stayed in the
                              # way uncleared, corridor_narrow seeds 2, 5, 7, 9) ...
SPU_SCAN_ROUND_EVERY = 3      # ... and every 3rd angle one of the rest of the circle, for the map (3.3.2) ...
SPU_SCAN_ROUND_STEP_DEG = 15  # ... in steps of the beam's width, round from the sweep's edge ...
SPU_SCAN_SIDE_DEG = (90, -90, 75, -75, 105, -105)   # ... but mostly the sides, left and right in turn, where a
SPU_SCAN_SIDES_PER_ROUND = 2  # wall alongside is followed: 2 side angles, then one of the rest of the circle
SPU_SCAN_NEAR_DEG = 15        # ... none off the sweep while an echo this close to the heading ...
SPU_SCAN_NEAR_M = 0.6         # ... is nearer than this (the NP3 avoids at 0.35 m; 2-3 s of walking before that)
SPU_FIRST_POLL = ("IRRC", "TPSC")  # after POST, before the alarm set-up: what touches or almost touches the body
SPU_STATUS_EVERY_S = 0.5      # one STATUS_REQ to a range sensor (USRC, IRRC in turn) this often (6.2)
SPU_SILENT_POLLS = 1          # failed transactions in a row (each with the retry) before OUT_OF_ORDER: the seed 3.2.2 rule
SPU_XMIT_RETRY_S = 0.3        # a pending record not granted this long: XMIT_REQ again (the request may be lost)
SPU_FORWARD = {               # VALUE records per (sensor, channel): (min change in raw steps or None, refresh s)
    "IRRC": (13, 2.0),        # 0.5 cm, the IR resolution the seed expects in practice (3.2.13)
    "USRC": (0, 0.0),         # every echo of the scan
    "TPSC": (0, 0.0),         # every contact
    "ISC": (3, 5.0),          # one 3 degree step (3.2.14)
    "TSC": (2, 10.0),         # 2 degrees C
    "LSC": (None, 2.0),       # every 2 s only: the NP3 fits its light gradient over samples spread in space
    "PSC": (4, 5.0),          # 20 mV
}
SPU_ALARM_IRRC_CM = 6.0       # SET_ALARM IRRC: an object closer than this (3.2.13; = NP3's "near")
SPU_ALARM_ISC_DEG = (15, 15)  # SET_ALARM ISC per axis (longitudinal, transverse): tilt beyond this either way (3.2.14)
SPU_ALARM_TSC_C = 50          # SET_ALARM TSC, every probe: hotter than this (3.2.15)
SPU_ALARM_LSC_LX = 500.0      # SET_ALARM LSC: brighter than this (3.2.16)
SPU_ALARM_PSC_V = 4.4         # SET_ALARM PSC: battery under-voltage below this, a quarter charge at rest (3.2.17);
                              # the PSC sees the loaded voltage: walking, it trips at about 40 % (fault_battery:
                              # open-circuit 4.515 V at the alarm, ~5 A through the battery's 0.05 ohm)

# --- sensor controllers (seed 3.2.11-3.2.17; all CHOICE: the seed gives no figures)
USRC_SPREAD_RAW = 8           # 3 sonar readings further apart than ~30 cm are suspect (3.2.11)
IRRC_SPREAD_RAW = 40          # 3 IR readings further apart than ~1.5 cm are suspect (3.2.13)
USRC_HEAD_STEP_S = 0.005      # time to turn the head by 1 degree
USRC_SECTOR_DEG = 10          # free run: announce the nearest echo of each sector this wide (one fetch per degree
                              # would need more than the 2400-baud sensor bus carries)
IRRC_MEASURE_S = 0.05         # the IRRC, ISC, TSC, LSC and PSC measure on their own clock (alarms, 3.2.13-3.2.17)
ISC_MEASURE_S = 0.2
TSC_MEASURE_S = 1.0           # all probes
LSC_MEASURE_S = 0.2           # the value sent is the mean of the last three (3.2.16)
PSC_MEASURE_S = 0.5           # the value sent is the mean of the last three (3.2.17)
PSC_ALARM_WINDOW_S = 5.0      # under-voltage: the highest of those means over this long is below the limit; a
                              # load dip (legs stalled against a wall) lasts shorter, an empty battery stays low
ALARM_REARM_RAW = {"IRRC": 26, "ISC": 3, "TSC": 2, "LSC": 6, "PSC": 4}   # hysteresis: an alarm re-arms once the
                              # value is back this many raw steps inside the limit (1 cm, 3 deg, 2 C, 20 %, 20 mV)
SENSOR_DATA_RDY_RETRY_S = 1.0 # a DATA_RDY nobody fetched is repeated after this long (a lost frame)
IRRC_NEAR_M = 0.06            # telemetry only: a new object this close ahead is a stimulus (5.2 latency)
TPSC_SCAN_S = 0.02            # whisker switch debounce / scan period

# --- MCP (seed 3.2.2, 3.2.17, 6.2, 6.3): supervision (all CHOICE)
MCP_MMC_POLL_S = 0.25         # STATUS_REQ to the MMC this often: a leg error (pit, blocked leg) reaches the NP3 fast
MCP_OBSTACLE_SPEAK_S = 10.0   # "Obstacle detected" at most this often
MCP_LED_BLINK_S = 0.5         # battery under-voltage: the MCP's LED toggles this often (3.2.17)

# --- level-0 nodes (seed 3.2.6-3.2.8, 4.1)
UIC_KEY_POLL_S = 0.05         # CHOICE: the UIC/RCP reads its RS-232 receive FIFO every 50 ms
APU_POLL_S = 0.05             # CHOICE: the APU/SDF looks for a new sound event every 50 ms ...
APU_PROCESS_S = 0.2           # CHOICE: ... and needs this long to find its direction (STATUS BUSY, 3.2.7)
APU_MIN_LEVEL_DB = 40.0       # CHOICE: quieter events (at the microphones) are not reported
