"""Behaviour tuning: every number the nodes' firmware chooses for itself, in one place.

None of these is a protocol rule: bus timing, retries, timeouts, POST rules
and set-point refresh come from the spec (arachnae_proto and
behaviours.netconfig). These are control periods, thresholds and rate limits
the seed leaves to the implementer (CHOICE); changing one changes how the
robot behaves, never what goes on the wire's format.
"""
from __future__ import annotations

# --- MMC (seed 3.2.4): gait clock and leg polling
MMC_CONTROL_S = 0.02          # gait generator period
MMC_POLL_S = 0.1              # one LEG_POLL every 100 ms, legs in turn

# --- LCP (seed 3.2.10, 6.1)
LCP_CONTROL_S = 0.1           # 10 Hz set points per joint, each with the speed to arrive in one period
LCP_BLOCK_CURRENT_A = 1.0     # above free-running servo current (0.35 A), below stall (1.8 A): leg blocked
LCP_SETTLE_S = 0.6            # a stance foot without ground contact this long after touchdown -> no ground
LCP_MIN_SPEED_DEG_S = 30.0    # slowest commanded joint speed: a joint catches up after a lost set point
LCP_SPEED_MARGIN = 2.0        # commanded speed = this x the speed needed to arrive within one period
LCP_RETRACT = 0.3             # seed 6.1: a blocked foot goes back this fraction towards its segment start
LCP_RETRY_MIN_S = 0.2         # shortest retried swing after a block
LCP_RETRY_CLEARANCE_M = 0.01  # retried swing lifts this much above the step limit

# --- JAC (seed 3.2.18)
JAC_STALL_CURRENT_A = 1.5     # motor current flagged STALLED | OVERCURRENT
JAC_AT_TARGET_RAD = 1e-3      # within this of the set point: AT_TARGET

# --- NP3 (seed 3.2.3, 5.1-5.2, decision 8)
NP3_PERIOD_S = 0.1            # subsumption layers evaluated every 100 ms
NP3_ESCAPE_BACK_S = 1.6       # back off one tripod cycle
NP3_ESCAPE_TURN_S = 3.2       # then turn for two cycles
NP3_IR_NEAR_M = 0.06          # an IR echo closer than this is an obstacle ahead
NP3_LIGHT_CHECK_S = 4.0       # light gradient check period (seek / avoid light)
NP3_EXPLORE_EVERY_S = 20      # explore: turn left every 20 s ...
NP3_EXPLORE_TURN_S = 1.6      # ... for one tripod cycle

# --- SPU (seed 3.2.5): polling order and forwarding rate limits to the NP3
SPU_CYCLE = ("IRRC", "USRC", "IRRC", "LSC", "IRRC", "ISC", "IRRC", "TSC", "IRRC", "PSC")  # IR every 2nd poll (5.2)
SPU_FORWARD_EVERY_S = {"LSC": 2.0, "USRC": 5.0}   # slowly changing values
SPU_IR_CHANGE_RAW = 8                             # forward an IR reading when it moved this many steps

# --- sensor controllers (seed 3.2.11-3.2.17)
USRC_SPREAD_RAW = 8           # 3 sonar readings further apart than ~30 cm are suspect (3.2.11)
IRRC_SPREAD_RAW = 40          # 3 IR readings further apart than ~1.5 cm are suspect (3.2.13)
USRC_HEAD_STEP_S = 0.005      # time to turn the head by 1 degree
IRRC_NEAR_M = 0.06            # telemetry only: a new object this close ahead is a stimulus (5.2 latency)
TPSC_SCAN_S = 0.02            # whisker switch debounce / scan period
