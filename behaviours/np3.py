"""NP3 (seed 3.2.3, 5.1-5.2, 6): navigation as layered behaviours (subsumption, decision 8).

Layers, highest priority first: stop when the IR sensor is unreliable (6.2);
escape a whisker or IR contact (5.2: react within about 1 s); then the task
(forward, explore, wall_follow, seek_light, avoid_light, idle). Each wish
becomes a MOVE record sent through the MCP's message scheduling (3.2.2):
XMIT_REQ, then MOVE when the MCP grants the bus.
"""
from __future__ import annotations

from arachnae_proto import messages as M
from arachnae_proto.enums import MovCmd, TpscContact
from arachnae_proto.network import ADDRESS_OF, NODES
from arachnae_proto.skeletons.np3 import Np3Skeleton

from behaviours import tuning as T
from behaviours.runtime import Runtime
from behaviours.units import quantizer

_IR = quantizer(M.XmitDataIrrc, "center")           # cm on the wire
_STOP, _FORWARD, _BACKWARD = int(MovCmd.STOP), int(MovCmd.FORWARD), int(MovCmd.BACKWARD)
_TURN_LEFT, _TURN_RIGHT, _TRIPOD = int(MovCmd.TURN_LEFT), int(MovCmd.TURN_RIGHT), int(MovCmd.TRIPOD)
_OBJ_LEFT = int(TpscContact.OBJ_LEFT)
_LATER = -1                                           # escape plan step: back to the task


class NP3(Runtime, Np3Skeleton):
    def start(self) -> None:
        self.running = False
        self.sent_cmd: int | None = None
        self.outbox: list[int] = []
        self.escape_until = -1.0
        self.escape_plan: list[tuple[float, int]] = []
        self.last_light: int | None = None
        self.light_check = 0.0
        self.ir_unreliable = False
        self.every(T.NP3_PERIOD_S, self.tick)

    def on_init(self, src: int, msg: M.Init) -> None:
        """seed 3.2.3: INIT from the MCP after POST starts navigation."""
        self.running = True
        self.want(_TRIPOD)
        self.want(self.task_command())

    def task_command(self) -> int:
        return _STOP if self.cfg.task == "idle" else _FORWARD

    # --- moving: XMIT_REQ -> XMIT_GRANT -> MOVE (seed 3.2.2) ---------------------------
    def want(self, mov_cmd: int) -> None:
        if mov_cmd == self.sent_cmd and not self.outbox:
            return
        self.outbox.append(mov_cmd)
        if len(self.outbox) == 1:
            self.slave_send(ADDRESS_OF["MCP"], M.XmitReq())

    def on_xmit_grant(self, src: int, msg: M.XmitGrant) -> None:
        if not self.outbox:
            if self.sent_cmd is not None:      # a repeated grant: our record did not get through
                self.send(src, M.Move(mov_cmd=self.sent_cmd, param=0))
            return
        mov = self.outbox.pop(0)
        self.sent_cmd = mov
        self.send(src, M.Move(mov_cmd=mov, param=0))
        if self.outbox:
            self.slave_send(src, M.XmitReq())

    # --- sensing --------------------------------------------------------------
    def on_data(self, src: int, msg: M.Data) -> None:
        if not self.running or msg.address not in NODES:
            return
        role, v = NODES[msg.address][1], msg.value
        if role == "TPSC" and v:
            self.escape(v)
        elif role == "IRRC":
            if _IR.phys(v) / 100 < T.NP3_IR_NEAR_M:
                self.escape(0)
        elif role == "LSC":
            self.light(v)

    def escape(self, contact: int) -> None:
        if self.ir_unreliable or self.now < self.escape_until:
            return
        turn = _TURN_RIGHT if contact == _OBJ_LEFT else _TURN_LEFT
        t = self.now
        self.escape_plan = [(t + T.NP3_ESCAPE_BACK_S, turn), (t + T.NP3_ESCAPE_BACK_S + T.NP3_ESCAPE_TURN_S, _LATER)]
        self.escape_until = t + T.NP3_ESCAPE_BACK_S + T.NP3_ESCAPE_TURN_S
        self.hw.note("escape", start=t, end=self.escape_until)
        self.want(_BACKWARD)

    def light(self, v: int) -> None:
        task = self.cfg.task
        if task not in ("seek_light", "avoid_light") or self.now < self.escape_until or self.now < self.light_check:
            return
        self.light_check = self.now + T.NP3_LIGHT_CHECK_S
        if self.last_light is not None:
            worse = v < self.last_light if task == "seek_light" else v > self.last_light
            if worse:
                self.escape_plan = [(self.now + T.NP3_ESCAPE_BACK_S, _LATER)]
                self.escape_until = self.now + T.NP3_ESCAPE_BACK_S
                self.want(_TURN_LEFT)
        self.last_light = v

    def tick(self) -> None:
        if not self.running or self.ir_unreliable:
            return
        t = self.now
        while self.escape_plan and t >= self.escape_plan[0][0]:
            _, cmd = self.escape_plan.pop(0)
            self.want(self.task_command() if cmd == _LATER else cmd)
        if self.cfg.task == "explore" and not self.escape_plan and int(t) % T.NP3_EXPLORE_EVERY_S == 0 \
                and t - int(t) < T.NP3_PERIOD_S:
            self.want(_TURN_LEFT)
            self.escape_plan = [(t + T.NP3_EXPLORE_TURN_S, _LATER)]
