"""MCP (seed 3.2.2): POST of the whole network, message scheduling on the first-level bus, supervision.

Supervision (6.2, 6.3, 3.2.17): the MCP polls the MMC's STATUS_ACK and tells
the NP3 when a leg error changes; it reads the records it relays and tells
the operator/supervisor (two-line LCD of the UIC/RCP, resident messages of
the SSC, only to those present after POST) about an unreliable or failed IR
or US sensor, leg errors, whisker contacts and the POST verdict; on battery
under-voltage it starts the UIC's beeper and blinks its own LED.
"""
from __future__ import annotations

from typing import TypedDict

from arachnae_proto import messages as M
from arachnae_proto.enums import Alert, Gait, MmcError, MovCmd, RangeStatus, RecordKind, SscMessage
from arachnae_proto.network import ADDRESS_OF, BROADCAST, NODES
from arachnae_proto.skeletons.mcp import McpSkeleton

from behaviours import tuning as T
from behaviours.post import PostMaster, Verdict, behind, verdict
from behaviours.runtime import PRIORITY_GRANT, PRIORITY_REFLEX, PRIORITY_RELAY, Runtime

_GAITS = frozenset(int(g) for g in Gait)
# seed 3.2.2: what a granted slave may answer with: the records the MCP receives (spec messages.<m>.record)
_RECORDS = tuple(cls for cls in McpSkeleton.RECEIVES if cls.RECORD)
_ALARM, _STATUS = int(RecordKind.ALARM), int(RecordKind.STATUS)
_IN_ORDER = int(RangeStatus.IN_ORDER)
_LCD_WIDTH = next(f for f in M.LcdText.FIELDS if f.name == "length").conv.hi
_NO_ERROR = int(MmcError.NONE)
# seed 3.2.4 error codes -> what the SSC says (seed 3.2.6 resident messages)
_SAY_LEG_ERROR = {int(MmcError.LEG_DRIVE_BLOCKED): SscMessage.LEG_BLOCKED,
                  int(MmcError.LEG_DRIVE_FAILED): SscMessage.MALFUNCTION,
                  int(MmcError.JAC_OUT_OF_ORDER): SscMessage.JAC_OUT_OF_ORDER,
                  int(MmcError.LCP_OUT_OF_ORDER): SscMessage.LCP_OUT_OF_ORDER}
# seed 6.2: who hears about a faulty range sensor, and what it means for the robot
_RANGE_FAULT = {"IRRC": ("operator", "IR", "ROBOT STOPPED"), "USRC": ("supervisor", "US", "DATA IGNORED")}


def lcd_lines(*lines: str) -> tuple[str, ...]:
    """Upper-case lines cut to the LCD's width (spec LCD_TEXT length)."""
    return tuple(line.upper()[:_LCD_WIDTH] for line in lines)


def top_missing(names: tuple[str, ...]) -> tuple[str, ...]:
    """The missing nodes not merely behind another missing one (docs/decisions.md D2): the MMC, not its 24 legs' nodes."""
    gone = {ADDRESS_OF[n] for n in names}
    hidden = {b for a in gone for b in behind(a)}
    return tuple(n for n in names if ADDRESS_OF[n] not in hidden)


def names_line(prefix: str, names: tuple[str, ...]) -> str:
    """'MISSING MMC,SPU' cut to the LCD width with a '+' when not all names fit."""
    text = prefix + ",".join(top_missing(names))
    return text if len(text) <= _LCD_WIDTH else text[:_LCD_WIDTH - 1] + "+"


class McpDebug(TypedDict):
    """MCP.debug_metrics(): metrics.json `nodes.MCP` (sim2d.metrics checks expectations on it at load)."""
    verdict: str | None
    missing: str
    faults: dict[str, int]          # node -> last non-zero status relayed
    posts: int
    halted: bool
    lcd_line0: str
    lcd_line1: str
    battery_low: bool
    operator: int                   # the counts: messages to the operator and supervisor, records, ...
    supervisor: int
    records: int
    alarms: int
    status_records: int
    mmc_status: int
    led_blinks: int


class MCP(PostMaster, Runtime, McpSkeleton):
    verdict: Verdict | None = None

    def start(self) -> None:
        self.requests: list[int] = []
        self.serving = False
        self.fetching: int | None = None                     # the slave granted the bus, whose record is due
        self.halted = False
        self.mmc_state: tuple[int, int] | None = None       # (error, leg) last told to the NP3
        self.faults: dict[tuple[int, int], int] = {}         # (source, channel) -> last non-zero status relayed
        self.polling_mmc = False
        self.battery_low = False
        self.led_on = False
        self.last_obstacle_msg = -1e9
        self.lcd = ("", "")
        self.counts = {"operator": 0, "supervisor": 0, "records": 0, "alarms": 0, "status_records": 0,
                       "mmc_status": 0, "led_blinks": 0}
        self.run_post(self.post_done)

    # --- POST (seed 6.3) -------------------------------------------------------------------
    def post_done(self, missing: list[int]) -> None:
        again = self.verdict is not None
        self.verdict = verdict(missing)
        v = self.verdict
        self.hw.note("post_verdict", verdict=v, run=self.post_runs)
        if v.verdict == "HALTED":
            # seed 3.2.2: a missing required node stops the robot and an error message is given (6.3)
            self.halted = True
            self.tell("operator", lcd_lines("POST HALTED", names_line("MISSING ", v.missing)), SscMessage.MALFUNCTION)
            if again and self.present("MMC"):
                self.request(ADDRESS_OF["MMC"], M.MoveRelayed(address=self.address, mov_cmd=int(MovCmd.STOP), param=0))
            return
        self.halted = False
        second = names_line("MISSING ", v.missing) if v.missing else "READY"
        self.tell("operator", lcd_lines(f"POST {v.verdict}", second), None)
        # seed 3.2.3: INIT via broadcasting (0xFF) on the first-level bus;
        # CHOICE: sent after a passed POST, it starts the NP3's navigation with a zeroed world model
        self.request(BROADCAST, M.Init())
        for (source, channel), value in sorted(self.faults.items()):
            # the NP3 starts afresh: what is known to be broken still is (6.2)
            self.request(ADDRESS_OF["NP3"], M.Data(address=source, kind=_STATUS, channel=channel, value=value,
                                                          age=0))   # the state now
        if self.present("MMC") and not self.polling_mmc:
            self.polling_mmc = True
            self.every(T.MCP_MMC_POLL_S, self.poll_mmc)

    def present(self, short: str) -> bool:
        """A node answered the last POST (messages go only to nodes that are there)."""
        return self.verdict is not None and short not in self.verdict.missing

    def on_post_req(self, src: int, msg: M.PostReq) -> None:
        """seed 6.3: POST can be started at any time from the UIC/RCP."""
        if not self._scheduled(src, msg) or self.post_missing is None:
            return                      # one is running
        self.hw.note("post_requested", by=NODES[src].short if src in NODES else src)
        self.run_post(self.post_done)

    # --- seed 3.2.2 message scheduling: serve the first XMIT_REQ that got through, then the next ---
    def on_xmit_req(self, src: int, msg: M.XmitReq) -> None:
        if src not in self.requests:
            self.requests.append(src)
        self._serve()

    def _serve(self) -> None:
        if self.serving or not self.requests:
            return
        self.serving = True
        # the requests held are served in arbitration rank (spec buses.first.priority: the SPU, which carries the
        # reflex records, first), before the MCP's own transactions still waiting out their defer (seed 3.2.2, 5.2)
        ranks = self.net.requesters.get(self.master_bus, ())
        src = min(self.requests, key=lambda a: ranks.index(a) if a in ranks else len(ranks))
        self.requests.remove(src)
        self.fetching = src
        self.request(src, M.XmitGrant(), _RECORDS, self._record, self._served, priority=PRIORITY_GRANT)

    def _served(self) -> None:
        self.serving = False
        self.fetching = None
        self._serve()

    def _record(self, src: int, msg: M.Message) -> None:
        """The granted slave's record goes to its generated on_ hook (on_move, on_xmit_record, on_post_req)."""
        self._handlers[type(msg)](src, msg)
        self._served()

    def _scheduled(self, src: int, msg: M.Message) -> bool:
        """seed 3.2.2: a record counts only as the answer to this MCP's XMIT_GRANT; one sent unasked is noted."""
        if src == self.fetching:
            return True
        self.hw.note("record_unasked", message=msg.NAME, src=NODES[src].short if src in NODES else src)
        return False

    def on_move(self, src: int, msg: M.Move) -> None:
        """seed 3.2.3/3.2.4: the NP3's (or the RCP's) MOVE goes on to the MMC as MOVE_RELAYED."""
        if self._scheduled(src, msg) and not self.halted:    # seed 3.2.2: a halted robot stays stopped
            # relayed before the next grant, like a record (the arbitration model's deliver step; at priority
            # 0 a steady flow of the SPU's records kept an NP3 MOVE from the MMC: tracecheck's K bound)
            self.relay_move(src, msg.mov_cmd, msg.param, 1 + self.net.protocol.move_retries, PRIORITY_RELAY)

    def on_xmit_record(self, src: int, msg: M.XmitRecord) -> None:
        """seed 3.2.2: a slave's record goes to its target as DATA (spec XMIT_RECORD relayed_as)."""
        if self._scheduled(src, msg) and msg.target == ADDRESS_OF["NP3"]:
            self.counts["records"] += 1
            self.reflex(msg)
            # the age passes on: the relay goes before the next grant, a frame at most later (issue 17)
            self.request(msg.target, M.Data(address=msg.source, kind=msg.kind, channel=msg.channel, value=msg.value,
                                            age=msg.age), priority=PRIORITY_RELAY)
            self.supervise(msg)

    def reflex(self, rec: M.XmitRecord) -> None:
        """seed 5.2, spec reflexes: a contact record passing through stops the legs at once, before the NP3 (which
        still gets the record) could; a halted robot is stopped already."""
        r = self.net.reflex_from(rec.source)
        if r is None or r.actor != self.address or not rec.value or rec.kind == _STATUS or self.halted:
            return
        self.hw.note("reflex", source=NODES[rec.source].short if rec.source in NODES else rec.source, command=r.command)
        self.relay_move(rec.source, int(MovCmd[r.command]), 0, 1 + self.net.protocol.move_retries, PRIORITY_REFLEX)

    def relay_move(self, src: int, mov_cmd: int, param: int, attempts: int, priority: int = 0) -> None:
        """MOVE_RELAYED has no reply of its own: the MMC's STATUS_ACK (gait, direction) confirms it.
        `priority` (a reflex's): both go ahead of everything of a lower one not yet on the wire."""
        mmc = ADDRESS_OF["MMC"]

        def check(s: int, ack: M.StatusAckMmc) -> None:
            self.mmc_status(ack)
            applied = ack.gait == mov_cmd if mov_cmd in _GAITS else ack.direction == mov_cmd
            if not applied and attempts > 1:       # spec protocol.move_retries
                self.relay_move(src, mov_cmd, param, attempts - 1, priority)
        self.request(mmc, M.MoveRelayed(address=src, mov_cmd=mov_cmd, param=param), priority=priority)
        self.request(mmc, M.StatusReq(), (M.StatusAckMmc,), check, priority=priority)

    # --- supervision ------------------------------------------------------------------------
    def poll_mmc(self) -> None:
        if self.post_missing is not None and self.present("MMC"):
            self.request(ADDRESS_OF["MMC"], M.StatusReq(), (M.StatusAckMmc,), lambda s, ack: self.mmc_status(ack))

    def mmc_status(self, ack: M.StatusAckMmc) -> None:
        """A changed (error, leg) goes to the NP3 as DATA(address=MMC, kind=STATUS, channel=leg) (6.1)."""
        state = (ack.error, ack.leg)
        if state == self.mmc_state:
            return
        self.mmc_state = state
        self.counts["mmc_status"] += 1
        mmc = ADDRESS_OF["MMC"]
        self.faults = {k: v for k, v in self.faults.items() if k[0] != mmc}
        if ack.error != _NO_ERROR:
            self.faults[(mmc, ack.leg)] = ack.error
        self.request(ADDRESS_OF["NP3"], M.Data(address=mmc, kind=_STATUS, channel=ack.leg, value=ack.error, age=0))
        if ack.error != _NO_ERROR:
            name = MmcError(ack.error).name.removeprefix("LEG_").replace("_", " ")
            self.tell("operator", lcd_lines(f"LEG {ack.leg}", name), _SAY_LEG_ERROR.get(ack.error))

    def supervise(self, rec: M.XmitRecord) -> None:
        """What a record passing through means for the operator or supervisor (6.2, 3.2.12, 3.2.17)."""
        role = NODES[rec.source].role if rec.source in NODES else ""
        if rec.kind == _STATUS:
            self.counts["status_records"] += 1
            key = (rec.source, rec.channel)
            if rec.value == _IN_ORDER:
                self.faults.pop(key, None)
            else:
                self.faults[key] = rec.value
            if role in _RANGE_FAULT and rec.value != _IN_ORDER:
                to, what, effect = _RANGE_FAULT[role]
                state = RangeStatus(rec.value).name.replace("_", " ")
                self.hw.note(f"{what.lower()}_fault", status=rec.value)
                self.tell(to, lcd_lines(f"{what} {state}", effect), SscMessage.MALFUNCTION)
        elif rec.kind == _ALARM:
            self.counts["alarms"] += 1
            if role == "PSC":
                self.battery_alarm()
        elif role == "TPSC" and rec.value and self.now - self.last_obstacle_msg >= T.MCP_OBSTACLE_SPEAK_S:
            self.last_obstacle_msg = self.now           # rate-limited
            self.tell("operator", lcd_lines("OBSTACLE", "WHISKER CONTACT"), SscMessage.OBSTACLE_DETECTED)

    def battery_alarm(self) -> None:
        """seed 3.2.17: under-voltage: the robot stops (the NP3's reflex), beeps and blinks."""
        if self.battery_low:
            return
        self.battery_low = True
        self.hw.note("battery_low")
        self.tell("operator", lcd_lines("BATTERY LOW", "ROBOT STOPPED"), None)
        if self.present("UIC/RCP"):
            self.request(ADDRESS_OF["UIC/RCP"], M.UicAlert(alert=int(Alert.BEEP | Alert.BLINK)))
        self.every(T.MCP_LED_BLINK_S, self.blink)

    def blink(self) -> None:
        self.led_on = not self.led_on
        self.counts["led_blinks"] += 1
        self.hw.note("led_blink", on=self.led_on)

    def tell(self, to: str, lines: tuple[str, ...], say: SscMessage | None) -> None:
        """An operator/supervisor message: the LCD lines to the UIC/RCP, a resident message to the SSC."""
        sent_to = []
        if self.present("UIC/RCP"):
            for i, line in enumerate(lines):
                self.request(ADDRESS_OF["UIC/RCP"], M.LcdText(line=i, text=line))
            sent_to.append("UIC/RCP")
            self.lcd = (lines + ("", ""))[:2]
        if say is not None and self.present("SSC"):
            self.request(ADDRESS_OF["SSC"], M.SpeakResident(repeat=1, length=0, index=int(say)))
            sent_to.append("SSC")
        self.counts[to] += 1
        self.hw.note("operator_message", text=" / ".join(lines), to=to, nodes=sent_to,
                     say=say.name if say is not None else None)

    def debug_metrics(self) -> McpDebug:
        v = self.verdict
        faults = {NODES[a].short: value for (a, _ch), value in sorted(self.faults.items()) if a in NODES}
        return {"verdict": v.verdict if v else None, "missing": ",".join(top_missing(v.missing)) if v else "",
                "faults": faults,
                "posts": self.post_runs, "halted": self.halted, "lcd_line0": self.lcd[0], "lcd_line1": self.lcd[1],
                "battery_low": self.battery_low, **self.counts}
