"""POST (seed 6.3, docs/decisions.md D2, D3): each master identifies its own
slaves with ID_REQ (bus response timeout, id_retries), asks each for its
status, then asks its sub-masters for their POST_REPORT; the MCP turns the
missing nodes into the verdict by the spec's declared rules.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

from arachnae_proto import messages as M
from arachnae_proto.network import NODES, POST, PostTable

from behaviours.runtime import slaves_of

# the health replies to STATUS_REQ (spec reply_to; busy/free is no health status, and its senders are not asked)
_STATUS_REPLIES = tuple(m for m in M.MESSAGES if m.REPLY_TO == M.StatusReq.NAME and m is not M.StatusAckBusy)


def _inactive_codes() -> frozenset[tuple[type[M.Message], int]]:
    """(reply, status code) pairs whose status names one of the POST's inactive statuses (seed 6.3)."""
    out = set()
    for cls in _STATUS_REPLIES:
        enum = next((f.enum for f in cls.FIELDS if f.name == "status" and f.enum is not None), None)
        if enum is not None:
            out |= {(cls, int(enum[s])) for s in POST.inactive_statuses if s in enum.__members__}  # type: ignore[attr-defined]
    return frozenset(out)


_INACTIVE = _inactive_codes()


@dataclass(frozen=True)
class Verdict:
    verdict: str                  # OPERATIONAL | DEGRADED | HALTED
    missing: tuple[str, ...]      # short names
    reasons: tuple[str, ...]


def behind(address: int) -> list[int]:
    """Every node reached only through `address` (docs/decisions.md D2): its bus's slaves, recursively."""
    bus = NODES[address].masters
    out: list[int] = []
    if bus is not None:
        for a in slaves_of(bus):
            out += [a] + behind(a)
    return out


def verdict(missing_addresses: list[int], post: PostTable = POST) -> Verdict:
    """HALTED when a required node outside every quorum or a quorum's minimum is lost,
    DEGRADED when an optional node or a quorum member is lost, else OPERATIONAL (spec post, generated)."""
    missing = {a for a in missing_addresses if a in NODES}
    halted: list[str] = []
    degraded: list[str] = []
    in_quorum: set[int] = set()
    for q in post.quorums:
        units: dict[int, list[int]] = {}
        for a, node in NODES.items():
            key = getattr(node, q.unit_key)            # spec post.quorums.unit_key: a NodeInfo field (leg)
            if node.role in q.unit_roles and key is not None:
                units.setdefault(key, []).append(a)
                in_quorum.add(a)
        complete = [k for k, members in units.items() if not missing.intersection(members)]
        if len(complete) < q.min_complete:
            halted.append(f"{q.name}: {len(complete)} of {len(units)} complete, at least {q.min_complete} needed")
        elif len(complete) < len(units):
            lost = sorted(set(units) - set(complete))
            degraded.append(f"{q.name}: {', '.join(str(k) for k in lost)} incomplete")
    for a, node in NODES.items():
        if a in missing and a not in in_quorum:
            (halted if node.required else degraded).append(
                f"{node.short} missing ({'required' if node.required else 'optional'})")
    names = tuple(sorted(NODES[a].short for a in missing))
    if halted:
        return Verdict("HALTED", names, tuple(halted))
    if degraded:
        return Verdict("DEGRADED", names, tuple(degraded))
    return Verdict("OPERATIONAL", (), ())


class _PostSteps:
    """One POST's transactions on the master's bus: the next step runs once these (and those their replies
    queue, e.g. STATUS_REQ after ID_ACK) are answered or timed out, whatever else the bus carries. Waiting for
    the whole bus to fall idle starved a POST run while walking (seed 6.3: POST at any time; post_rerun seed 2:
    the MMC's gait traffic kept its leg bus busy for 5 s, its report came too late and the verdict was HALTED)."""

    def __init__(self, master: "PostMaster") -> None:
        self.master = master
        self.open = 0                                   # transactions queued and not yet finished
        self.next: Callable[[], None] | None = None

    def request(self, dst: int, msg: M.Message, expect: tuple, on_reply: Callable[..., None],
                on_timeout: Callable[[], None], retries: int, timeout: float | None = None) -> None:
        self.open += 1

        def reply(src: int, m: M.Message) -> None:
            on_reply(src, m)
            self._settle()

        def silent() -> None:
            on_timeout()
            self._settle()
        self.master.request(dst, msg, expect, reply, silent, retries, timeout)  # type: ignore[attr-defined]

    def then(self, fn: Callable[[], None]) -> None:
        """Run fn once every transaction of this POST so far has finished (at once if none is open)."""
        if self.open == 0:
            fn()
        else:
            self.next = fn

    def _settle(self) -> None:
        self.open -= 1
        if self.open == 0 and self.next is not None:
            fn, self.next = self.next, None
            fn()


class PostMaster:
    """Mixin (before Runtime) for every bus master: runs POST on its bus and answers POST_QUERY."""

    post_missing: list[int] | None = None      # None until this master's POST has finished
    post_runs = 0                              # how many POSTs this master has run
    _post_reported = False                     # its last POST's result went upward
    _post_callback: Callable[[list[int]], None] | None = None

    def run_post(self, done: Callable[[list[int]], None] | None = None) -> None:
        self.post_missing = None
        self.post_runs += 1
        self._post_reported = False
        self._post_callback = done
        self._post_waiting: list[int] = getattr(self, "_post_waiting", [])
        missing: list[int] = []
        retries = self.links[self.master_bus].timing.id_retries          # type: ignore[attr-defined]
        steps = _PostSteps(self)

        def lost(a: int) -> None:
            missing.append(a)
            missing.extend(behind(a))

        for a in slaves_of(self.master_bus):                              # type: ignore[attr-defined]
            def on_status(src: int, msg: M.Message, a: int = a) -> None:
                hook = getattr(self, "post_status", None)
                if hook is not None:
                    hook(a, msg)                                           # the master keeps its slaves' status
                if (type(msg), getattr(msg, "status", None)) in _INACTIVE:
                    lost(a)                                                # seed 6.3: declares itself inactive

            def on_ack(src: int, msg: M.Message, a: int = a) -> None:
                if NODES[a].role in M.StatusAckBusy.SENDERS:
                    return                                                 # busy / free is no health status
                steps.request(a, M.StatusReq(), _STATUS_REPLIES, on_status, lambda a=a: lost(a), retries)
            steps.request(a, M.IdReq(), (M.IdAck,), on_ack, lambda a=a: lost(a), retries)

        def finish() -> None:
            self.post_missing = sorted(set(missing))
            self.hw.note("post_report", node=self.name, missing=self.post_missing)  # type: ignore[attr-defined]
            for src in self._post_waiting:
                self._post_report(src)
            self._post_waiting.clear()
            if done is not None:
                done(self.post_missing)

        def query_subs() -> None:
            def on_report(src: int, msg: M.PostReport) -> None:
                missing.extend(msg.missing)
            for a in slaves_of(self.master_bus):                          # type: ignore[attr-defined]
                if NODES[a].masters is not None and a not in missing:
                    steps.request(a, M.PostQuery(), (M.PostReport,), on_report, lambda a=a: lost(a), retries,
                                  self.net.protocol.post_report_timeout_s)  # type: ignore[attr-defined]
            steps.then(finish)

        steps.then(query_subs)

    def on_id_req(self, src: int, msg: M.IdReq) -> None:
        """seed 6.3: POST can be started at any time. A sub-master asked for its ID again after it reported
        its last POST (the master runs a new POST) runs its own POST again, so the new report is fresh."""
        super().on_id_req(src, msg)                                        # type: ignore[misc]
        if self._post_reported and self.post_missing is not None:
            self.hw.note("post_rerun", node=self.name)                     # type: ignore[attr-defined]
            self.run_post(self._post_callback)

    def on_post_query(self, src: int, msg: M.PostQuery) -> None:
        """seed 6.3: report when this master's own POST is done."""
        if self.post_missing is None:
            self.__dict__.setdefault("_post_waiting", []).append(src)
        else:
            self._post_report(src)

    def _post_report(self, src: int) -> None:
        self._post_reported = True
        self.send(src, M.PostReport(missing=self.post_missing or []))     # type: ignore[attr-defined]
