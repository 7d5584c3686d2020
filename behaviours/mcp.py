"""MCP (seed 3.2.2): POST of the whole network, then message scheduling on the first-level bus."""
from __future__ import annotations

from arachnae_proto import messages as M
from arachnae_proto.enums import Gait
from arachnae_proto.network import ADDRESS_OF
from arachnae_proto.skeletons.mcp import McpSkeleton

from behaviours.post import PostMaster, Verdict, verdict
from behaviours.runtime import Runtime

_GAITS = frozenset(int(g) for g in Gait)


class MCP(PostMaster, Runtime, McpSkeleton):
    verdict: Verdict | None = None

    def start(self) -> None:
        self.requests: list[int] = []
        self.serving = False
        self.run_post(self.post_done)

    def post_done(self, missing: list[int]) -> None:
        self.verdict = verdict(self.net, missing)
        self.hw.note("post_verdict", verdict=self.verdict)
        if self.verdict.verdict == "HALTED":
            return          # seed 3.2.2: a missing required node stops the robot
        # CHOICE: INIT to the NP3 after a passed POST starts navigation with a zeroed world model (seed 3.2.3)
        self.request(ADDRESS_OF["NP3"], M.Init())

    # seed 3.2.2 message scheduling: serve the first XMIT_REQ that got through, then the next
    def on_xmit_req(self, src: int, msg: M.XmitReq) -> None:
        if src not in self.requests:
            self.requests.append(src)
        self._serve()

    def _serve(self) -> None:
        if self.serving or not self.requests:
            return
        self.serving = True
        src = self.requests.pop(0)
        self.request(src, M.XmitGrant(), (M.Move, M.XmitRecord), self._record, self._served)

    def _served(self) -> None:
        self.serving = False
        self._serve()

    def _record(self, src: int, msg: M.Message) -> None:
        if isinstance(msg, M.Move):
            self.relay_move(src, msg.mov_cmd, msg.param, 1 + self.net.protocol.move_retries)
        elif isinstance(msg, M.XmitRecord) and msg.target == ADDRESS_OF["NP3"]:
            self.request(msg.target, M.Data(address=msg.source, kind=msg.kind, channel=msg.channel, value=msg.value))
        self._served()

    def relay_move(self, src: int, mov_cmd: int, param: int, attempts: int) -> None:
        """MOVE_RELAYED has no reply of its own: the MMC's STATUS_ACK (gait, direction) confirms it."""
        mmc = ADDRESS_OF["MMC"]

        def check(s: int, ack: M.StatusAckMmc) -> None:
            applied = ack.gait == mov_cmd if mov_cmd in _GAITS else ack.direction == mov_cmd
            if not applied and attempts > 1:       # spec protocol.move_retries
                self.relay_move(src, mov_cmd, param, attempts - 1)
        self.request(mmc, M.MoveRelayed(address=src, mov_cmd=mov_cmd, param=param))
        self.request(mmc, M.StatusReq(), (M.StatusAckMmc,), check)

    def on_post_req(self, src: int, msg: M.PostReq) -> None:
        """seed 6.3: POST can be started at any time from the UIC/RCP."""
        self.run_post(self.post_done)
