"""SPU (seed 3.2.5): master of the sensor bus; polls the sensors and forwards to the NP3.

After its POST it sets the USRC scanning (FREE_RUN) and polls the other
sensors round-robin (tuning.SPU_CYCLE), the IRRC every second poll because
close range matters most (5.2). A DATA_RDY is served before the next poll.
Values the NP3 needs travel as XMIT_RECORDs through the MCP (3.2.2).
"""
from __future__ import annotations

from arachnae_proto import messages as M
from arachnae_proto.network import ADDRESS_OF, NODES
from arachnae_proto.skeletons.spu import SpuSkeleton

from behaviours import tuning as T
from behaviours.post import PostMaster
from behaviours.runtime import Runtime, slaves_of

# each sensor role's XMIT_DATA reply (the spec's XMIT_DATA_<role> layouts)
REPLY_OF = {m.SENDERS[0]: m for m in M.MESSAGES if m.SEED_NAME == "XMIT_DATA" and m is not M.XmitData}


class SPU(PostMaster, Runtime, SpuSkeleton):
    def start(self) -> None:
        self.sensors = {NODES[a][1]: a for a in slaves_of(self.master_bus)}
        self.outbox: list[tuple[int, int]] = []
        self.last_fwd: dict[str, tuple[float, int]] = {}
        self.cycle_i = 0
        self.live: list[str] = []
        self.last_record: tuple[int, int] | None = None
        self.run_post(self.post_done)

    def post_done(self, missing: list[int]) -> None:
        self.live = [r for r in T.SPU_CYCLE if r in self.sensors and self.sensors[r] not in missing]
        if "USRC" in self.live:
            self.request(self.sensors["USRC"], M.FreeRun())
        self.poll()

    def poll(self) -> None:
        if not self.live:
            return
        role = self.live[self.cycle_i % len(self.live)]
        self.cycle_i += 1
        self.request(self.sensors[role], M.XmitData(), (REPLY_OF[role],),
                     lambda s, msg, role=role: self.got(role, msg, True), self.poll, 0)

    def on_data_rdy(self, src: int, msg: M.DataRdy) -> None:
        role = NODES[src][1]
        if role in REPLY_OF:
            self.request(src, M.XmitData(), (REPLY_OF[role],), lambda s, m, role=role: self.got(role, m, False),
                         urgent=True)

    def got(self, role: str, msg: M.Message, polled: bool) -> None:
        if role == "TPSC":
            self.forward(role, msg.contact)
        elif role == "IRRC":
            v = min(msg.left, msg.center, msg.right)
            last = self.last_fwd.get(role)
            if last is None or abs(last[1] - v) >= T.SPU_IR_CHANGE_RAW:
                self.forward(role, v)
        elif role in T.SPU_FORWARD_EVERY_S:
            last = self.last_fwd.get(role)
            if last is None or self.now - last[0] >= T.SPU_FORWARD_EVERY_S[role]:
                self.forward(role, msg.brightness if role == "LSC" else msg.distance)
        if polled:
            self.poll()

    def forward(self, role: str, value: int) -> None:
        self.last_fwd[role] = (self.now, value)
        src = self.sensors[role]
        self.outbox = [(a, v) for a, v in self.outbox if a != src] + [(src, value)]
        if len(self.outbox) == 1:
            self.slave_send(ADDRESS_OF["MCP"], M.XmitReq())

    def on_xmit_grant(self, src: int, msg: M.XmitGrant) -> None:
        np3 = ADDRESS_OF["NP3"]
        if not self.outbox:
            if self.last_record is not None:   # a repeated grant: the record did not get through
                source, value = self.last_record
                self.send(src, M.XmitRecord(target=np3, source=source, kind=0, channel=0, value=value))
            return
        source, value = self.outbox.pop(0)
        self.last_record = (source, value)
        self.send(src, M.XmitRecord(target=np3, source=source, kind=0, channel=0, value=value))
        if self.outbox:
            self.slave_send(src, M.XmitReq())
