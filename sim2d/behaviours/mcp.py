"""MCP (seed 3.2.2): POST of the whole network, then message scheduling on the first-level bus."""
from __future__ import annotations


from sim2d.behaviours.base import Master, Request
from sim2d.post import verdict

RELAY_ATTEMPTS = 3   # CHOICE: a MOVE is relayed at most three times until the MMC's status shows it


class MCP(Master):
    def start(self) -> None:
        self.requests: list[int] = []
        self.serving = False
        self.run_post(self.post_done)

    def post_done(self, missing: list[int]) -> None:
        spec = self.ctx.spec
        result = verdict(spec, missing)
        self.ctx.set_verdict(result)
        if result.verdict == "HALTED":
            return          # seed 3.2.2: a missing required node stops the robot
        np3 = spec.node("NP3")
        # CHOICE: INIT to the NP3 after a passed POST starts navigation with a zeroed world model (seed 3.2.3)
        self.request("first", Request(np3.address, "INIT", {}))

    # 3.2.2 message scheduling: serve the first XMIT_REQ that got through, then the next
    def on_xmit_req(self, bus: str, src: int, f: dict) -> None:
        if src not in self.requests:
            self.requests.append(src)
        self._serve()

    def _serve(self) -> None:
        if self.serving or not self.requests:
            return
        self.serving = True
        src = self.requests.pop(0)
        self.request("first", Request(src, "XMIT_GRANT", {}, ("MOVE", "XMIT_RECORD"), self._record, self._served))

    def _served(self) -> None:
        self.serving = False
        self._serve()

    def _record(self, src: int, name: str, f: dict) -> None:
        spec = self.ctx.spec
        if name == "MOVE":
            self.relay_move(src, f["mov_cmd"], f["param"], RELAY_ATTEMPTS)
        elif name == "XMIT_RECORD":
            target = spec.node_at(f["target"])
            if target is not None and target.role == "NP3":
                self.request("first", Request(target.address, "DATA", {"address": f["source"], "value": f["value"]}))
        self._served()

    def relay_move(self, src: int, mov_cmd: int, param: int, attempts: int) -> None:
        """MOVE_RELAYED has no reply of its own: the MMC's STATUS_ACK (gait, direction) confirms it."""
        mmc = self.ctx.spec.node("MMC").address
        gaits = self.ctx.spec.enums["GAIT"].values.values()

        def check(s: int, name: str, f: dict) -> None:
            applied = f["gait"] == mov_cmd if mov_cmd in gaits else f["direction"] == mov_cmd
            if not applied and attempts > 1:
                self.relay_move(src, mov_cmd, param, attempts - 1)
        self.request("first", Request(mmc, "MOVE_RELAYED", {"address": src, "mov_cmd": mov_cmd, "param": param}))
        self.request("first", Request(mmc, "STATUS_REQ", {}, ("STATUS_ACK_MMC",), check))

    def on_post_req(self, bus: str, src: int, f: dict) -> None:
        self.run_post(self.post_done)
