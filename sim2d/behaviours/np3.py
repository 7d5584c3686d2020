"""NP3 (seed 3.2.3, 5.1-5.2, 6): navigation as layered behaviours (subsumption, decision 8).

Layers, highest priority first: stop when the IR sensor is unreliable (6.2);
escape a whisker or IR contact (5.2: react within about 1 s); then the task
(forward, explore, wall_follow, seek_light, avoid_light, idle). Each wish
becomes a MOVE record sent through the MCP's message scheduling (3.2.2).
"""
from __future__ import annotations

from sim2d import encodings as enc
from sim2d.behaviours.base import NodeProcess

ESCAPE_BACK_S = 1.6      # CHOICE: back off one tripod cycle
ESCAPE_TURN_S = 3.2      # CHOICE: then turn for two cycles
IR_NEAR_M = 0.06         # CHOICE: an IR echo closer than this is an obstacle ahead
LIGHT_CHECK_S = 4.0      # CHOICE: light gradient check period for seek/avoid light


class NP3(NodeProcess):
    tick_period = 0.1

    def start(self) -> None:
        self.running = False
        self.sent_cmd: int | None = None
        self.outbox: list[int] = []
        self.escape_until = -1.0
        self.escape_plan: list[tuple[float, int]] = []
        self.last_light: int | None = None
        self.light_check = 0.0
        self.ir_unreliable = False
        self.cmd = self.ctx.spec.enums["MOV_CMD"].values

    def on_init(self, bus: str, src: int, f: dict) -> None:
        self.running = True
        self.want(self.cmd["TRIPOD"])
        self.want(self.task_command())

    def task_command(self) -> int:
        task = self.ctx.scenario.task
        if task == "idle":
            return self.cmd["STOP"]
        return self.cmd["FORWARD"]

    # --- moving: XMIT_REQ -> XMIT_GRANT -> MOVE (seed 3.2.2) ---------------------------
    def want(self, mov_cmd: int) -> None:
        if mov_cmd == self.sent_cmd and not self.outbox:
            return
        self.outbox.append(mov_cmd)
        if len(self.outbox) == 1:
            self.slave_send("first", self.ctx.spec.node("MCP").address, "XMIT_REQ")

    def on_xmit_grant(self, bus: str, src: int, f: dict) -> None:
        if not self.outbox:
            if self.sent_cmd is not None:      # a repeated grant: our record did not get through
                self.reply(bus, src, "MOVE", mov_cmd=self.sent_cmd, param=0)
            return
        mov = self.outbox.pop(0)
        self.sent_cmd = mov
        self.reply(bus, src, "MOVE", mov_cmd=mov, param=0)
        if self.outbox:
            self.slave_send("first", src, "XMIT_REQ")

    # --- sensing --------------------------------------------------------------
    def on_data(self, bus: str, src: int, f: dict) -> None:
        if not self.running:
            return
        node = self.ctx.spec.node_at(f["address"])
        if node is None:
            return
        v = f["value"]
        if node.role == "TPSC" and v:
            self.escape(v)
        elif node.role == "IRRC":
            if enc.irrc_metres(v) < IR_NEAR_M:
                self.escape(0)
        elif node.role == "LSC":
            self.light(v)

    def escape(self, contact: int) -> None:
        if self.ir_unreliable or self.now < self.escape_until:
            return
        flags = self.ctx.spec.flags["TPSC_CONTACT"].bits
        turn = self.cmd["TURN_RIGHT"] if contact == flags["OBJ_LEFT"] else self.cmd["TURN_LEFT"]
        t = self.now
        self.escape_plan = [(t + ESCAPE_BACK_S, turn), (t + ESCAPE_BACK_S + ESCAPE_TURN_S, -1)]
        self.escape_until = t + ESCAPE_BACK_S + ESCAPE_TURN_S
        self.ctx.escaping(t, self.escape_until)
        self.want(self.cmd["BACKWARD"])

    def light(self, v: int) -> None:
        task = self.ctx.scenario.task
        if task not in ("seek_light", "avoid_light") or self.now < self.escape_until or self.now < self.light_check:
            return
        self.light_check = self.now + LIGHT_CHECK_S
        if self.last_light is not None:
            worse = v < self.last_light if task == "seek_light" else v > self.last_light
            if worse:
                self.escape_plan = [(self.now + ESCAPE_BACK_S, -1)]
                self.escape_until = self.now + ESCAPE_BACK_S
                self.want(self.cmd["TURN_LEFT"])
        self.last_light = v

    def tick(self, t: float) -> None:
        if not self.running or self.ir_unreliable:
            return
        while self.escape_plan and t >= self.escape_plan[0][0]:
            _, cmd = self.escape_plan.pop(0)
            self.want(self.task_command() if cmd < 0 else cmd)
        if self.ctx.scenario.task == "explore" and not self.escape_plan and int(t) % 20 == 0 and t - int(t) < self.tick_period:
            self.want(self.cmd["TURN_LEFT"])
            self.escape_plan = [(t + 1.6, -1)]
