"""Guarded-command models: variables, rules, properties, symmetry.

A model is data, not code, so one description feeds both our checker and the
Promela emitter. Every rule is one atomic step `guard -> effect` (effects run in
order, like a Promela d_step), which is what makes SPIN's stored-state count
comparable with ours.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable

from model_check import expr


@dataclass(frozen=True)
class Var:
    """An integer variable ranging over 0..hi, packed into the state as a bit field."""

    name: str
    hi: int
    init: int = 0
    doc: str = ""

    @property
    def bits(self) -> int:
        return max(1, self.hi.bit_length())


@dataclass(frozen=True)
class Event:
    """One arrow (or note when dst is None) of a message sequence chart."""

    src: str
    dst: str | None
    text: str


@dataclass(frozen=True)
class Rule:
    """One transition. `actor` is the weak-fairness group (None: environment, never forced)."""

    name: str
    guard: str
    effect: tuple[tuple[str, str], ...] = ()
    actor: str | None = None
    ticks: int = 0
    msc: tuple[Event, ...] = ()


@dataclass(frozen=True)
class Invariant:
    name: str
    expr: str
    doc: str = ""


@dataclass(frozen=True)
class Response:
    """Liveness `G(trigger -> F goal)` checked under weak fairness; also yields a tick bound."""

    name: str
    trigger: str
    goal: str
    doc: str = ""


@dataclass(frozen=True)
class SymGroup:
    """Interchangeable blocks of variables (same layout, contiguous, in order).

    Groups are applied in list order, so inner groups (joints of a leg) must come
    before the outer group (the legs) for the canonical form to be unique.
    """

    name: str
    blocks: tuple[tuple[str, ...], ...]


@dataclass
class Model:
    name: str
    vars: list[Var]
    rules: list[Rule]
    invariants: list[Invariant] = field(default_factory=list)
    final: str = "False"                     # terminal states satisfying this are not deadlocks
    responses: list[Response] = field(default_factory=list)
    symmetry: list[SymGroup] = field(default_factory=list)
    # Final-state checks written in Python (e.g. an independent oracle); our checker only.
    final_checks: list[tuple[str, Callable[[dict[str, int]], str | None]]] = field(default_factory=list)
    # What the final checks see, as (name, expression) pairs (default: every variable), and the checks
    # in bulk: view arrays of many final states -> True where a check reports a problem. The engine
    # screens every final state with it and runs `final_checks` (for the message) on those it flags.
    final_view: list[tuple[str, str]] = field(default_factory=list)
    final_screen: Callable[[dict[str, Any]], Any] | None = None
    tick_us: float = 0.0                     # duration of one tick, for reporting bounds
    bound_ms: float | None = None            # the spec's bound on the responses' worst case (requirements)
    bound_section: str = ""
    notes: list[str] = field(default_factory=list)
    origin: dict[str, str] = field(default_factory=dict)     # what it was built from (model, bus, variant)
    participants: list[str] = field(default_factory=list)   # MSC column order
    # Named subexpressions over the variables, evaluated once per state (Promela: #define).
    defs: list[tuple[str, str]] = field(default_factory=list)

    def __post_init__(self) -> None:
        self.validate()

    def var(self, name: str) -> Var:
        return self._by_name[name]

    def validate(self) -> None:
        self._by_name = {v.name: v for v in self.vars}
        if len(self._by_name) != len(self.vars):
            raise expr.ExprError(f"{self.name}: duplicate variable names")
        for v in self.vars:
            if not (0 <= v.init <= v.hi) or not v.name.isidentifier():
                raise expr.ExprError(f"{self.name}: bad variable {v}")
        known = set(self._by_name)
        for name, text in self.defs:
            unknown = expr.names(text) - known
            if unknown or not name.isidentifier():
                raise expr.ExprError(f"{self.name}: definition {name} uses unknown names {sorted(unknown)}")
            known.add(name)
        assigned_ok = set(self._by_name)

        def check(text: str, where: str) -> None:
            unknown = expr.names(text) - known
            if unknown:
                raise expr.ExprError(f"{self.name}: {where} uses unknown names {sorted(unknown)}")

        rule_names = set()
        for r in self.rules:
            if r.name in rule_names:
                raise expr.ExprError(f"{self.name}: duplicate rule {r.name}")
            rule_names.add(r.name)
            check(r.guard, r.name)
            for target, value in r.effect:
                if target not in assigned_ok:
                    raise expr.ExprError(f"{self.name}: {r.name} assigns unknown {target}")
                if expr.names(value) - assigned_ok:   # a #define would see updated values in SPIN
                    raise expr.ExprError(f"{self.name}: {r.name}: effects may use variables only")
        for inv in self.invariants:
            check(inv.expr, inv.name)
        check(self.final, "final")
        for name, text in self.final_view:
            check(text, f"final view {name}")
        for resp in self.responses:
            check(resp.trigger, resp.name)
            check(resp.goal, resp.name)
        for g in self.symmetry:
            widths = {tuple(self._by_name[n].bits for n in b) for b in g.blocks}
            if len(widths) != 1:
                raise expr.ExprError(f"{self.name}: symmetry group {g.name} has blocks of different layout")

    @property
    def initial(self) -> dict[str, int]:
        return {v.name: v.init for v in self.vars}
