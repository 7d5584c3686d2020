"""SPU (seed 3.2.5): master of the sensor bus; polls the sensors and forwards to the NP3.

After its POST it sets the USRC scanning (FREE_RUN) and polls the other
sensors round-robin, the IRRC every second poll because close range matters
most (5.2). A TPSC DATA_RDY is served before the next poll. Values the NP3
needs travel as XMIT_RECORDs through the MCP (3.2.2).
"""
from __future__ import annotations

from sim2d.behaviours.base import Master, Request

CYCLE = ("IRRC", "USRC", "IRRC", "LSC", "IRRC", "ISC", "IRRC", "TSC", "IRRC", "PSC")   # CHOICE
FORWARD_EVERY_S = {"LSC": 2.0, "USRC": 5.0}   # CHOICE: rate limits for slowly changing values
IR_CHANGE = 8                                 # CHOICE: forward an IR reading when it moved this many steps


class SPU(Master):
    def start(self) -> None:
        spec = self.ctx.spec
        self.sensors = {n.role: n for n in spec.slaves(self.node.masters)}
        self.reply_of = {m.senders[0]: m.name for m in spec.messages if m.seed_name == "XMIT_DATA" and m.name != "XMIT_DATA"}
        self.outbox: list[tuple[int, int]] = []
        self.last_fwd: dict[str, tuple[float, int]] = {}
        self.cycle_i = 0
        self.last_record: tuple[int, int] | None = None
        self.run_post(self.post_done)

    def post_done(self, missing: list[int]) -> None:
        self.live = [r for r in CYCLE if r in self.sensors and self.sensors[r].address not in missing]
        if "USRC" in self.live:
            self.request(self.node.masters, Request(self.sensors["USRC"].address, "FREE_RUN", {}))
        self.poll()

    def poll(self) -> None:
        if not self.live:
            return
        role = self.live[self.cycle_i % len(self.live)]
        self.cycle_i += 1
        n = self.sensors[role]
        self.request(self.node.masters, Request(n.address, "XMIT_DATA", {}, (self.reply_of[role],),
                                                lambda s, name, f, role=role: self.got(role, f, True), self.poll, 0))

    def on_data_rdy(self, bus: str, src: int, f: dict) -> None:
        node = self.ctx.spec.node_at(src)
        if node is None or node.role not in self.reply_of:
            return
        link = self.links[bus]
        link.queue.appendleft(Request(src, "XMIT_DATA", {}, (self.reply_of[node.role],),
                                      lambda s, name, f, role=node.role: self.got(role, f, False), None, 1))
        if link.current is None:
            self._next(link)

    def got(self, role: str, f: dict, polled: bool) -> None:
        if role == "TPSC":
            self.forward(role, f["contact"])
        elif role == "IRRC":
            v = min(f["left"], f["center"], f["right"])
            last = self.last_fwd.get(role)
            if last is None or abs(last[1] - v) >= IR_CHANGE:
                self.forward(role, v)
        elif role in FORWARD_EVERY_S:
            last = self.last_fwd.get(role)
            if last is None or self.now - last[0] >= FORWARD_EVERY_S[role]:
                self.forward(role, f["brightness"] if role == "LSC" else f["distance"])
        if polled:
            self.poll()

    def forward(self, role: str, value: int) -> None:
        self.last_fwd[role] = (self.now, value)
        src = self.sensors[role].address
        self.outbox = [(a, v) for a, v in self.outbox if a != src] + [(src, value)]
        if len(self.outbox) == 1:
            self.slave_send("first", self.ctx.spec.node("MCP").address, "XMIT_REQ")

    def on_xmit_grant(self, bus: str, src: int, f: dict) -> None:
        if not self.outbox:
            if self.last_record is not None:   # a repeated grant: the record did not get through
                source, value = self.last_record
                self.reply(bus, src, "XMIT_RECORD", target=self.ctx.spec.node("NP3").address, source=source, value=value)
            return
        source, value = self.outbox.pop(0)
        self.last_record = (source, value)
        self.reply(bus, src, "XMIT_RECORD", target=self.ctx.spec.node("NP3").address, source=source, value=value)
        if self.outbox:
            self.slave_send("first", src, "XMIT_REQ")
