"""Response properties G(trigger -> F goal) under weak fairness, with lassos and tick bounds.

A violation is a reachable trigger state from which the run can stay out of
`goal` forever along a weakly fair cycle (or end in a final state). The states
that can do so form a subgraph B; an SCC of B is fair when every fairness group
enabled throughout it is also taken inside it (weak fairness, checked per SCC,
which is exact because a walk can cover the whole SCC). When B has no cycle at
all, the longest tick-weighted path through it is the response bound K.
"""
from __future__ import annotations

from collections import deque

from model_check.engine import Result, Violation, follow, trace_to


def check_responses(res: Result) -> None:
    for index, resp in enumerate(res.model.responses):
        bound, violation = check_response(res, index)
        res.bounds[resp.name] = bound
        if violation is not None:
            res.violation = violation
            return


def _sccs(nodes: list[int], adj: dict[int, list[tuple[int, int]]]) -> list[list[int]]:
    """Tarjan, iteratively; SCCs come out successors-first (reverse topological order)."""
    index: dict[int, int] = {}
    low: dict[int, int] = {}
    on: set[int] = set()
    stack: list[int] = []
    out: list[list[int]] = []
    counter = 0
    for root in nodes:
        if root in index:
            continue
        work = [(root, iter(adj[root]))]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on.add(root)
        while work:
            v, it = work[-1]
            advanced = False
            for _, w in it:
                if w not in index:
                    index[w] = low[w] = counter
                    counter += 1
                    stack.append(w)
                    on.add(w)
                    work.append((w, iter(adj[w])))
                    advanced = True
                    break
                if w in on and index[w] < low[v]:
                    low[v] = index[w]
            if advanced:
                continue
            work.pop()
            if work and low[v] < low[work[-1][0]]:
                low[work[-1][0]] = low[v]
            if low[v] == index[v]:
                comp = []
                while True:
                    w = stack.pop()
                    on.discard(w)
                    comp.append(w)
                    if w == v:
                        break
                out.append(comp)
    return out


def check_response(res: Result, index: int) -> tuple[int | None, Violation | None]:
    model, comp = res.model, res.compiled
    resp = model.responses[index]
    trig, goal = comp.predicates[f"trigger{index}"], comp.predicates[f"goal{index}"]
    actors = [r.actor for r in model.rules]
    ticks = [r.ticks for r in model.rules]
    canon, succ = comp.canon, comp.successors

    roots = [s for s in res.seen if trig(s) and not goal(s)]
    adj: dict[int, list[tuple[int, int]]] = {}     # edges staying in B
    exits: dict[int, list[int]] = {}               # rules leaving B (reaching goal)
    enabled: dict[int, set] = {}
    todo = list(roots)
    for s in roots:
        adj[s] = []
    while todo:
        s = todo.pop()
        inside, out, groups = [], [], set()
        for rule, ns in succ(s):
            groups.add(actors[rule])
            ns = canon(ns)
            if goal(ns):
                out.append(rule)
            else:
                inside.append((rule, ns))
                if ns not in adj:
                    adj[ns] = []
                    todo.append(ns)
        adj[s] = inside
        exits[s] = out
        enabled[s] = groups

    sccs = _sccs(list(adj), adj)
    for scc in sccs:
        members = set(scc)
        edges = [(u, r, v) for u in scc for r, v in adj[u] if v in members]
        terminal = len(scc) == 1 and not adj[scc[0]] and not exits[scc[0]]
        if not edges and not terminal:
            continue
        if terminal or _fair(scc, edges, enabled, actors):
            return None, _lasso(res, resp.name, roots, adj, scc, edges, enabled, actors, terminal)

    if any(len(c) > 1 or any(v == c[0] for _, v in adj[c[0]]) for c in sccs):
        return None, None          # holds only thanks to fairness: no tick bound
    longest: dict[int, int] = {}
    for scc in sccs:               # successors first
        s = scc[0]
        best = max((ticks[r] for r in exits[s]), default=0)
        for r, v in adj[s]:
            best = max(best, ticks[r] + longest[v])
        longest[s] = best
    return max((longest[s] for s in roots), default=0), None


def _fair(scc: list[int], edges, enabled, actors) -> bool:
    taken = {actors[r] for _, r, _ in edges}
    always = set.intersection(*(enabled[s] for s in scc))
    return all(g is None or g in taken for g in always)


def _bfs_path(start: int, goal_test, adj, allowed: set[int] | None) -> list[int]:
    """States after `start` up to the first satisfying goal_test (start itself excluded)."""
    parent = {start: None}
    queue = deque([start])
    while queue:
        u = queue.popleft()
        for _, v in adj[u]:
            if v in parent or (allowed is not None and v not in allowed):
                continue
            parent[v] = u
            if goal_test(v):
                path = [v]
                while parent[path[-1]] != start:
                    path.append(parent[path[-1]])
                return path[::-1]
            queue.append(v)
    raise RuntimeError("no path")  # pragma: no cover


def _lasso(res, name, roots, adj, scc, edges, enabled, actors, terminal) -> Violation:
    comp = res.compiled
    members = set(scc)
    # shortest way from some trigger state into the SCC (multi-source BFS inside B)
    parent = {r: None for r in roots}
    queue = deque(roots)
    entry = next((r for r in roots if r in members), None)
    while entry is None and queue:
        u = queue.popleft()
        for _, v in adj[u]:
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
    steps = trace_to(res, chain[0])
    steps += follow(comp, steps[-1].state, chain[1:])
    loop_start = len(steps) - 1
    if terminal:
        return Violation("liveness", name, steps, loop_start,
                         detail="the run ends in a final state without reaching the goal")
    # the cycle must take, or pass a state disabling, every group enabled somewhere in it
    cycle: list[int] = []
    cur = entry
    groups = set().union(*(enabled[s] for s in scc)) - {None}
    for g in sorted(groups, key=str):
        edge = next(((u, v) for u, r, v in edges if actors[r] == g), None)
        if edge is not None:
            u, v = edge
            if cur != u:
                cycle += _bfs_path(cur, lambda x, u=u: x == u, adj, members)
            cycle.append(v)
            cur = v
        else:
            if g in enabled[cur]:
                cycle += _bfs_path(cur, lambda x, g=g: g not in enabled[x], adj, members)
                cur = cycle[-1]
    if cur != entry or not cycle:
        cycle += _bfs_path(cur, lambda x: x == entry, adj, members)
    steps += follow(comp, steps[-1].state, cycle)
    return Violation("liveness", name, steps, loop_start,
                     detail="a weakly fair cycle in which the goal never holds")
