"""Response properties G(trigger -> F goal) under weak fairness, with lassos and tick bounds.

A violation is a reachable trigger state from which the run can stay out of
`goal` forever along a weakly fair cycle (or end in a final state). The states
that can do so form a subgraph B; an SCC of B is fair when every fairness group
enabled throughout it is also taken inside it (weak fairness, checked per SCC,
which is exact because a walk can cover the whole SCC). When B has no cycle at
all, the longest tick-weighted path through it is the response bound K.

Everything runs on the graph the search stored (model_check.storage), with
numpy (issue 12: no second pass over the states): trigger and goal are
evaluated on all stored states at once; B is a breadth-first closure over the
edge arrays; peeling B from its sinks (Kahn's algorithm, one vectorised step
per level) gives the longest path when B is acyclic and leaves exactly the
states that reach a cycle otherwise; only those go to scipy's strongly
connected components, and fairness is an AND/OR of per-state group bitmasks
over each SCC. Python loops over states remain only to build a counterexample.
"""
from __future__ import annotations

import time
from collections import deque
from typing import TYPE_CHECKING, NamedTuple

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import connected_components

from model_check import native
from model_check.storage import pieces, ranges
from model_check.trace import Violation, concretise, follow

if TYPE_CHECKING:
    from model_check.engine import Result


def check_responses(res: Result) -> None:
    """Every response in turn, on the compiled pass (model_check.native) where the search had
    one; a violation's counterexample, and everything without it, comes from the numpy algorithm
    below (both decide the same: tests/model_check/test_native.py)."""
    fast = _Native(res) if res.native is not None else None
    graph: _Graph | None = None
    for index, resp in enumerate(res.model.responses):
        answer = fast.check(index) if fast is not None else None
        if answer is not None:
            res.bounds[resp.name] = answer.bound
            continue
        graph = graph or _Graph(res)
        bound, violation = check_response(res, index, graph)
        res.bounds[resp.name] = bound
        if violation is not None:
            res.violation = violation
            return


class _Rules:
    """Per rule: its fairness group (actor), the group's bit, and its ticks."""

    def __init__(self, model):
        self.actors = [r.actor for r in model.rules]
        groups = sorted({a for a in self.actors if a is not None})
        if len(groups) > 64:       # pragma: no cover - no model comes close
            raise ValueError(f"{model.name}: more than 64 fairness groups")
        bit = {g: 1 << k for k, g in enumerate(groups)}
        self.bit = np.array([bit.get(a, 0) for a in self.actors] or [0], np.uint64)
        self.ticks = np.array([r.ticks for r in model.rules] or [0], np.int32)


class _Answer(NamedTuple):
    bound: int | None          # the response bound K in ticks; None: holds under weak fairness only


class _Native(_Rules):
    """The responses on the compiled pass: triggers and goals of 16 responses at a time
    evaluated in C in one pass over the stored states (bits of a uint32 per state), then per
    response one iterative Tarjan over B that yields the bound K, or decides weak fairness per
    cyclic component; 12 bytes per state of work arrays, no reverse graph."""

    GROUP = 16                 # responses whose trigger and goal share one uint32 per state

    def __init__(self, res: Result):
        super().__init__(res.model)
        self.res, self.nat, self.store = res, res.native, res._graph()
        n = len(self.store)
        self.mask = np.empty(n, np.uint32)
        self.work = np.empty((2, n), np.int32)
        self.group = -1

    def decide(self, index: int) -> tuple[int, int]:
        """(native.L_* kind, bound) of response `index`."""
        t = time.process_time()
        group, k = divmod(index, self.GROUP)
        if group != self.group:       # predicate 1 + 2i is response i's trigger, 2 + 2i its goal
            first = 1 + 2 * group * self.GROUP
            last = min(first + 2 * self.GROUP, 1 + 2 * len(self.res.model.responses))
            self.nat.predicates(first, last, self.store.keys.view, self.mask)
            self.group = group
        t = _tick(self.res, "liveness", t)
        st = self.store
        kind, bound = self.nat.respond(st.offsets, st.dst.view, st.rule.view, self.mask, 2 * k, 2 * k + 1,
                                       self.ticks, self.bit, self.work)
        _tick(self.res, "bounds" if kind == native.L_BOUND else "liveness", t)
        return kind, bound

    def check(self, index: int) -> _Answer | None:
        """The answer, or None where the numpy algorithm must say it (a violation: it builds the
        counterexample; or the C pass ran out of memory or int32 ticks)."""
        kind, bound = self.decide(index)
        if kind == native.L_BOUND:
            return _Answer(bound)
        return _Answer(None) if kind == native.L_FAIR_ONLY else None


class _Graph(_Rules):
    """What every response of one result shares: per-rule fairness bits and ticks, the reverse edges."""

    def __init__(self, res: Result):
        model, store = res.model, res._graph()
        t = time.process_time()
        super().__init__(model)
        n = len(store)
        rev = csr_matrix((store.rule.view, store.dst.view, store.offsets), shape=(n, n)).tocsc()
        self.rev_ptr, self.rev_src, self.rev_rule = rev.indptr, rev.indices, rev.data
        _tick(res, "liveness", t)


def _sinks(off: np.ndarray, ids: np.ndarray) -> np.ndarray:
    """The states among `ids` without a successor, a slice at a time."""
    out = [part[off[part + 1] == off[part]] for part in np.array_split(ids, max(1, len(ids) >> 20))]
    return np.concatenate(out) if out else ids[:0]


def _tick(res: Result, key: str, since: float) -> float:
    now = time.process_time()
    res.times[key] = res.times.get(key, 0.0) + now - since
    return now


def check_response(res: Result, index: int, graph: _Graph | None = None) -> tuple[int | None, Violation | None]:
    graph = graph or _Graph(res)
    model, comp, store = res.model, res.compiled, res._graph()
    resp = model.responses[index]
    off, dst, rule = store.offsets, store.dst.view, store.rule.view
    t = time.process_time()
    goal = store.mask(comp.layout, model.defs, resp.goal)
    roots = np.flatnonzero(store.mask(comp.layout, model.defs, resp.trigger) & ~goal).astype(np.int32)
    if not roots.size:
        _tick(res, "liveness", t)
        return 0, None
    # B: reachable from the roots without passing a goal state
    in_b = np.zeros(len(store), bool)
    in_b[roots] = True
    fr = roots
    while fr.size:
        found = []
        for part in pieces(off, fr):
            v = dst[ranges(off, part)]
            v = v[~goal[v] & ~in_b[v]]
            in_b[v] = True
            found.append(v)
        fr = np.unique(np.concatenate(found)).astype(np.int32)
    b = np.flatnonzero(in_b).astype(np.int32)       # int32 ids: these arrays can span every state
    sub = _SubGraph(store, goal, b)
    terminal = _sinks(off, b)        # the run ends (a final state) without reaching the goal
    if terminal.size:
        _tick(res, "liveness", t)
        return None, _lasso(res, resp.name, roots, sub, [int(terminal[0])], [], graph, True)
    # per state of B: edges staying in B, and the most ticks of an edge leaving it (into goal),
    # a slice of B at a time so that no array has one entry per edge
    outdeg = np.zeros(len(store), np.int32)
    longest = np.zeros(len(store), np.int32)
    for part in pieces(off, b):
        e = ranges(off, part)
        into = goal[dst[e]]
        src = np.repeat(part, off[part + 1] - off[part])
        outdeg[part] = np.bincount(src[~into] - part[0], minlength=int(part[-1] - part[0] + 1))[part - part[0]]
        np.maximum.at(longest, src[into], graph.ticks[rule[e[into]]])
    t = _tick(res, "liveness", t)
    # peel B from its sinks: longest tick path where acyclic; what is left reaches a cycle
    ready = b[outdeg[b] == 0]
    peeled = 0
    while ready.size:
        peeled += ready.size
        touched = []
        for part in pieces(graph.rev_ptr, ready):
            e = ranges(graph.rev_ptr, part)
            via = np.repeat(longest[part], graph.rev_ptr[part + 1] - graph.rev_ptr[part])
            u = graph.rev_src[e]
            keep = in_b[u]
            u = u[keep]
            np.maximum.at(longest, u, graph.ticks[graph.rev_rule[e[keep]]] + via[keep])
            uu, cnt = np.unique(u, return_counts=True)
            outdeg[uu] -= cnt
            touched.append(uu)
        uu = np.unique(np.concatenate(touched))
        ready = uu[outdeg[uu] == 0]
    if peeled == len(b):
        _tick(res, "bounds", t)
        return int(longest[roots].max()), None
    t = _tick(res, "bounds", t)
    # strongly connected components of what reaches a cycle; a fair one is a violation
    left = b[outdeg[b] > 0]
    in_left = outdeg > 0
    in_left[~in_b] = False
    e = ranges(off, left)
    s2 = np.repeat(np.arange(len(left)), off[left + 1] - off[left])
    d2, r2 = dst[e], rule[e]
    keep = in_left[d2]
    s2, d2, r2 = s2[keep], np.searchsorted(left, d2[keep]), r2[keep]
    n2 = len(left)
    _, label = connected_components(csr_matrix((np.ones(len(s2), np.int8), (s2, d2)), shape=(n2, n2)),
                                    directed=True, connection="strong")
    cyclic = np.bincount(label) > 1
    cyclic[label[s2[s2 == d2]]] = True
    # weak fairness per SCC: every group enabled in all its states is taken inside it
    enabled = np.bitwise_or.reduceat(graph.bit[rule[e]], np.concatenate(([0], np.cumsum(off[left + 1] - off[left])[:-1])))
    always = np.full(len(cyclic), np.uint64(0xFFFFFFFFFFFFFFFF))
    np.bitwise_and.at(always, label, enabled)
    taken = np.zeros(len(cyclic), np.uint64)
    same = label[s2] == label[d2]
    np.bitwise_or.at(taken, label[s2[same]], graph.bit[r2[same]])
    fair = np.flatnonzero(cyclic & ((always & ~taken) == 0))
    _tick(res, "liveness", t)
    if not fair.size:
        return None, None              # holds only thanks to fairness: no tick bound
    members = left[label == fair[0]].tolist()
    inside_scc = set(members)
    edges = [(u, ru, v) for u in members for ru, v in sub.adj(u) if v in inside_scc]
    return None, _lasso(res, resp.name, roots, sub, members, edges, graph, False)


class _SubGraph:
    """B's edges and the enabled groups of one state, as Python values (for counterexamples)."""

    def __init__(self, store, goal: np.ndarray, b: np.ndarray):
        self.store, self.goal, self.b = store, goal, b

    def adj(self, u: int) -> list[tuple[int, int]]:
        st = self.store
        lo, hi = int(st.offsets[u]), int(st.offsets[u + 1])
        return [(int(r), int(v)) for r, v in zip(st.rule.view[lo:hi], st.dst.view[lo:hi]) if not self.goal[v]]

    def rules_of(self, u: int) -> list[int]:
        st = self.store
        return st.rule.view[int(st.offsets[u]):int(st.offsets[u + 1])].tolist()


def _bfs_path(start: int, goal_test, adj, allowed: set[int] | None) -> list[int]:
    """States after `start` up to the first satisfying goal_test (start itself excluded)."""
    parent = {start: None}
    queue = deque([start])
    while queue:
        u = queue.popleft()
        for _, v in adj(u):
            if allowed is not None and v not in allowed:
                continue
            if goal_test(v):           # `start` too: a cycle back to it (a self-loop) is a path
                path = [v]
                while u != start:
                    path.append(u)
                    u = parent[u]
                return path[::-1]
            if v not in parent:
                parent[v] = u
                queue.append(v)
    raise RuntimeError("no path")  # pragma: no cover


def _lasso(res, name, roots, graph: _SubGraph, scc: list[int], edges, rules: _Graph, terminal) -> Violation:
    comp, store = res.compiled, res._graph()
    actors = rules.actors
    members = set(scc)
    # shortest way from some trigger state into the SCC (multi-source BFS inside B)
    roots = roots.tolist()
    parent = {r: None for r in roots}
    queue = deque(roots)
    entry = next((r for r in roots if r in members), None)
    while entry is None and queue:
        u = queue.popleft()
        for _, v in graph.adj(u):
            if v not in parent:
                parent[v] = u
                if v in members:
                    entry = v
                    break
                queue.append(v)
    chain = [entry]
    while parent[chain[-1]] is not None:
        chain.append(parent[chain[-1]])
    chain.reverse()
    steps = concretise(comp, store.states(store.path_to(chain[0])))
    steps += follow(comp, steps[-1].state, store.states(chain[1:]))
    loop_start = len(steps) - 1
    if terminal:
        return Violation("liveness", name, steps, loop_start,
                         detail="the run ends in a final state without reaching the goal")

    def enabled(u: int) -> set:
        return {actors[r] for r in graph.rules_of(u)}
    # the cycle must take, or pass a state disabling, every group enabled somewhere in it
    cycle: list[int] = []
    cur = entry
    groups = set().union(*(enabled(s) for s in scc)) - {None}
    for g in sorted(groups, key=str):
        edge = next(((u, v) for u, r, v in edges if actors[r] == g), None)
        if edge is not None:
            u, v = edge
            if cur != u:
                cycle += _bfs_path(cur, lambda x, u=u: x == u, graph.adj, members)
            cycle.append(v)
            cur = v
        else:
            if g in enabled(cur):
                cycle += _bfs_path(cur, lambda x, g=g: g not in enabled(x), graph.adj, members)
                cur = cycle[-1]
    if cur != entry or not cycle:
        cycle += _bfs_path(cur, lambda x: x == entry, graph.adj, members)
    steps += follow(comp, steps[-1].state, store.states(cycle))
    return Violation("liveness", name, steps, loop_start,
                     detail="a weakly fair cycle in which the goal never holds")
