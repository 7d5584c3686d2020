"""POST (seed 6.3): hierarchical identification and the verdict, over every node condition.

The MCP tests itself, then identifies its slaves in address order; a sub-master
that answers identifies its own slaves the same way and reports upward with
POST_REPORT (docs/decisions.md D2). Each identification is one step with the
outcomes the id_retry model proves the ID_REQ/timeout/retry exchange can end
in: present (ID_ACK), absent or mute (no ID_ACK after the retry) and
out-of-order (ID_ACK but a status in post.inactive_statuses). A mute or
out-of-order sub-master is never heard, so what its own slaves do cannot reach
the MCP and is not explored. The NODES table starts all-inactive (seed 3.2.2)
and the verdict is computed from it by the spec's rule; an independent oracle
recomputes the verdict from the node conditions and the hierarchy.

Children that share role, status and subtree shape (the legs, the joints of a
leg) are identified in any order and declared symmetric, so the full network
is decided with symmetry reduction.

Abstracted away, and checked on bus traces by tracecheck instead:
- the broadcast INIT after a POST that did not halt (seed 3.2.3): it follows
  the verdict and changes no NODES entry; the validator checks one INIT per
  passed POST and none after a HALTED one;
- corruption of ID_REQ / ID_ACK frames and late answers: one identification
  step stands for the whole exchange, whose outcomes the id_retry model
  proves (a corrupt frame fails its CRC and counts as lost there); the
  validator checks each exchange's timeout and retries on the wire;
- the sub-masters' relays (SPU, MMC, LCP: POST_QUERY / POST_REPORT): a
  sub-master's report is its own POST over its bus, i.e. the sub-tree here;
  the validator recomputes the verdict from every bus's own ID exchanges
  (`expected_verdict`), so a sub-master reporting wrongly is caught too.
"""
from __future__ import annotations

import numpy as np

from model_check.expr import all_of, any_of, count_of
from model_check.gcl import Event, Invariant, Model, Rule, SymGroup, Var
from model_check.spec_adapter import PostNode, PostParams

UNTESTED, OK, MISSING = 0, 1, 2
VERDICT = {"OPERATIONAL": 1, "DEGRADED": 2, "HALTED": 3}
NAMES = {code: name for name, code in VERDICT.items()}
OUTCOMES = ("absent", "mute", "out_of_order")


class Tree:
    def __init__(self, p: PostParams, legs: int | None):
        self.p = p
        keep = [n for n in p.nodes if legs is None or n.leg is None or n.leg <= legs]
        self.by = {n.short: n for n in keep}
        self.children: dict[str, list[PostNode]] = {n.short: [] for n in keep}
        for n in keep:
            if n.master is not None:
                self.children[n.master].append(n)
        self.var = {}
        self.order: list[PostNode] = []
        self._number(p.root)

    def _number(self, short: str) -> None:
        """DFS order; the leg/joint blocks come out contiguous for the symmetry groups."""
        for c in self.children[short]:
            self.var[c.short] = f"x{len(self.var)}"
            self.order.append(c)
            self._number(c.short)

    def shape(self, short: str) -> tuple:
        n = self.by[short]
        return (self.p.roles[short], n.required, tuple(sorted(self.shape(c.short) for c in self.children[short])))

    def symmetric(self, short: str) -> bool:
        kids = self.children[short]
        return len(kids) > 1 and len({self.shape(c.short) for c in kids}) == 1

    def subtree(self, short: str) -> list[str]:
        out = []
        for c in self.children[short]:
            out.append(c.short)
            out += self.subtree(c.short)
        return out


def build(p: PostParams, legs: int | None = None, symmetry: bool = True) -> Model:
    t = Tree(p, legs)
    x = t.var
    vs = [Var("mcp", 2, doc="MCP self test: 0 pending, 1 passed, 2 failed")]
    vs += [Var(x[n.short], 2, doc=f"NODES[{n.short}]: 0 not asked, 1 active, 2 missing") for n in t.order]
    vs.append(Var("vd", 3, doc="verdict: 0 none, 1 OPERATIONAL, 2 DEGRADED, 3 HALTED"))
    root = p.root
    rules = [Rule("mcp_selftest_pass", "mcp == 0", (("mcp", "1"),), actor="MCP", msc=(Event(root, None, "self test passed"),)),
             Rule("mcp_selftest_fail", "mcp == 0", (("mcp", "2"),), actor=None, msc=(Event(root, None, "self test failed"),))]

    def decided(short: str) -> str:
        """The sub-tree of `short` has been identified and reported."""
        kids = t.children[short]
        own = f"{x[short]} != {UNTESTED}" if short != root else "mcp == 1"
        if not kids:
            return own
        inner = all_of(decided(c.short) for c in kids)
        return f"{own} and ({x[short]} == {MISSING} or ({inner}))" if short != root else f"{own} and ({inner})"

    def may_probe(parent: str, k: int) -> str:
        kids = t.children[parent]
        up = "mcp == 1" if parent == root else f"{x[parent]} == {OK}"
        if t.symmetric(parent):
            # interchangeable siblings: any order, one sub-tree at a time (one master, one bus)
            busy = [f"({x[c.short]} == {OK} and not ({decided(c.short)}))" for c in kids if t.children[c.short]]
            return f"{up} and not ({any_of(busy)})" if busy else up
        prev = kids[k - 1].short if k else None
        return f"{up} and ({decided(prev)})" if prev else up

    for parent in [root] + [n.short for n in t.order]:
        for k, c in enumerate(t.children[parent]):
            g = f"{x[c.short]} == {UNTESTED} and {may_probe(parent, k)}"
            # seed 3.2.2: ID_REQ, 10 ms, one retry (proved by the id_retry model); seed 6.3: report upward
            rules.append(Rule(f"id_{c.short}_present", g, ((x[c.short], str(OK)),), actor=parent,
                              msc=(Event(parent, c.short, "ID_REQ"), Event(c.short, parent, "ID_ACK"))))
            for o in OUTCOMES:
                rules.append(Rule(f"id_{c.short}_{o}", g, ((x[c.short], str(MISSING)),), actor=None,
                                  msc=(Event(parent, c.short, "ID_REQ"),
                                       Event(c.short, parent, "ID_ACK OUT_OF_ORDER" if o == "out_of_order"
                                             else f"no ID_ACK after the retry ({o})"))))

    # the verdict, by the spec's rule over the NODES table
    everything = [n.short for n in t.order]
    units: dict[tuple[str, int], list[str]] = {}
    for name, key, _, roles in p.quorums:
        for s in everything:
            n = t.by[s]
            if p.roles[s] in roles and getattr(n, key) is not None:
                units.setdefault((name, getattr(n, key)), []).append(s)
    in_quorum = {s for members in units.values() for s in members}
    missing = {s: f"{x[s]} != {OK}" for s in everything}
    quorum_low, quorum_short = [], []
    for name, key, least, _ in p.quorums:
        mine = [m for (q, _), m in units.items() if q == name]
        complete = count_of(all_of(f"{x[s]} == {OK}" for s in m) for m in mine)
        quorum_low.append(f"({complete}) < {least}")            # seed 6.3: at least five legs
        quorum_short.append(f"({complete}) < {len(mine)}")
    halted = any_of(["mcp == 2"] + [missing[s] for s in everything if t.by[s].required and s not in in_quorum]
                    + quorum_low)
    degraded = any_of([missing[s] for s in everything if not t.by[s].required] + quorum_short)
    ready = f"vd == 0 and (mcp == 2 or ({decided(root)}))"
    rules += [
        Rule("verdict_HALTED", f"{ready} and ({halted})", (("vd", "3"),), actor="MCP",
             msc=(Event(root, None, "POST verdict HALTED"),)),
        Rule("verdict_DEGRADED", f"{ready} and not ({halted}) and ({degraded})", (("vd", "2"),), actor="MCP",
             msc=(Event(root, None, "POST verdict DEGRADED"),)),
        Rule("verdict_OPERATIONAL", f"{ready} and not ({halted}) and not ({degraded})", (("vd", "1"),),
             actor="MCP", msc=(Event(root, None, "POST verdict OPERATIONAL"),)),
    ]
    invs = [Invariant("verdict_only_when_done", f"vd == 0 or mcp == 2 or ({decided(root)})"),
            Invariant("failed_mcp_halts", "vd == 0 or mcp != 2 or vd == 3")]
    sym: list[SymGroup] = []
    if symmetry:
        for parent in [n.short for n in t.order]:          # inner groups (joints) first ...
            if t.symmetric(parent) and not any(t.children[c.short] for c in t.children[parent]):
                sym.append(SymGroup(f"children of {parent}", tuple((x[c.short],) for c in t.children[parent])))
        for parent in [root] + [n.short for n in t.order]:  # ... then the groups containing them
            if t.symmetric(parent) and any(t.children[c.short] for c in t.children[parent]):
                blocks = tuple(tuple(x[s] for s in [c.short] + t.subtree(c.short)) for c in t.children[parent])
                sym.append(SymGroup(f"subtrees under {parent}", blocks))
    names = {x[s]: s for s in everything}
    model = Model(name=f"post[{len(everything) + 1} nodes{', symmetry' if sym else ''}]", vars=vs, rules=rules,
                  invariants=invs, final="vd != 0", symmetry=sym, participants=[root] + everything[:0],
                  notes=["seed 6.3 POST; each identification abstracted to its outcome (see id_retry)"])
    model.final_checks.append(("verdict_matches_oracle", lambda v: oracle_mismatch(p, t, names, v)))
    # the oracle sees the self test, the verdict and who answered, on every final state at once
    model.final_view = [("mcp", "mcp"), ("vd", "vd")] + [(x[s], f"{x[s]} == {OK}") for s in everything]
    model.final_screen = lambda view: oracle_screen(p, t, names, view)
    return model


def expected_verdict(p: PostParams, t: Tree, answered: dict[str, bool], mcp_ok: bool = True) -> tuple[str, set[str]]:
    """seed 6.3, by the spec's rule: the verdict and the required nodes it must name, from which nodes
    answered their identification (`answered`, short -> bool, every node of the tree) and the hierarchy.

    The independent oracle of this model, and the rule the trace validator holds the MCP's verdict to
    (one case of `expected_verdicts`)."""
    codes, named = expected_verdicts(p, t, {s: np.array([a], bool) for s, a in answered.items()},
                                     np.array([mcp_ok], bool))
    return NAMES[int(codes[0])], {s for s, m in named.items() if m[0]}


def expected_verdicts(p: PostParams, t: Tree, answered: dict[str, np.ndarray],
                      mcp_ok: np.ndarray) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """`expected_verdict` for many cases at once (one bool array per node, aligned): the verdicts
    (VERDICT codes) and, per node, in which cases the verdict must name it. The model checker
    runs it on every final state in bulk (issue 12); the trace validator on one case."""
    known: dict[str, np.ndarray] = {}

    def present(s: str) -> np.ndarray:
        if s not in known:
            n = t.by[s]
            known[s] = (mcp_ok if n.master == p.root else present(n.master)) & answered[s]
        return known[s]

    absent = {s: ~present(s) for s in answered}
    named = {s: a for s, a in absent.items() if t.by[s].required}
    halted = np.zeros_like(mcp_ok)
    degraded = np.zeros_like(mcp_ok)
    for name, key, least, roles in p.quorums:
        groups: dict[int, list[str]] = {}
        for s in answered:
            if p.roles[s] in roles and getattr(t.by[s], key) is not None:
                groups.setdefault(getattr(t.by[s], key), []).append(s)
        members = {s for g in groups.values() for s in g}
        whole = sum(np.logical_and.reduce([present(s) for s in g]).astype(np.int64) for g in groups.values())
        low = np.asarray(whole < least)
        outside = np.logical_or.reduce([m for s, m in named.items() if s not in members] + [np.zeros_like(low)])
        halted = halted | low | outside
        degraded = degraded | (whole < len(groups))
        for s in members & named.keys():
            named[s] = named[s] & low            # a tolerated missing leg is no reason to halt
    degraded = degraded | np.logical_or.reduce([a for s, a in absent.items() if not t.by[s].required]
                                               + [np.zeros_like(mcp_ok)])
    if not p.quorums:
        halted = halted | np.logical_or.reduce(list(named.values()) + [np.zeros_like(mcp_ok)])
    # a failed self test halts and names the MCP alone
    halted = halted | ~mcp_ok
    named = {s: m & mcp_ok for s, m in named.items()}
    named[p.root] = named.get(p.root, np.zeros_like(mcp_ok)) | ~mcp_ok
    codes = np.where(halted, VERDICT["HALTED"], np.where(degraded, VERDICT["DEGRADED"], VERDICT["OPERATIONAL"]))
    return codes, named


def oracle_screen(p: PostParams, t: Tree, names: dict[str, str], view: dict[str, np.ndarray]) -> np.ndarray:
    """`oracle_mismatch` on many final views at once: True where it reports a problem."""
    mcp_ok = view["mcp"] != 2
    answered = {names[k]: v != 0 for k, v in view.items() if k in names}
    codes, named = expected_verdicts(p, t, answered, mcp_ok)
    halted = (codes == VERDICT["HALTED"]) & (view["vd"] == VERDICT["HALTED"])
    # a HALTED report names the required nodes that did not answer: one named but answered is missing
    unreported = np.logical_or.reduce([named[s] & answered[s] for s in answered if s in named]
                                      + [np.zeros_like(mcp_ok)])
    return np.where(halted, mcp_ok & unreported, codes != view["vd"])


def oracle_mismatch(p: PostParams, t: Tree, names: dict[str, str], values: dict[str, int]) -> str | None:
    """Independent oracle: verdict and missing required nodes straight from conditions and the hierarchy.

    `values` is the model's final view: mcp, vd and, per node variable, 1 if the node answered."""
    answered = {names[k]: bool(v) for k, v in values.items() if k in names}
    expect, named = expected_verdict(p, t, answered, values["mcp"] != 2)
    got = NAMES[values["vd"]]
    reported = {p.root} if values["mcp"] == 2 else {s for s in answered if t.by[s].required and not answered[s]}
    if expect == "HALTED" and got == "HALTED":
        if values["mcp"] != 2 and not (named <= reported):
            return f"HALTED report {sorted(reported)} does not name {sorted(named - reported)}"
        return None
    if got != expect:
        absent = sorted(s for s in answered if not answered[s])
        return f"verdict {got}, oracle says {expect} (missing: {absent})"
    return None
