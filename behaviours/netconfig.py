"""Spec rules the behaviours need that the generated package does not carry yet.

Wire facts (addresses, routes, bus baud rates and timeouts, message classes),
each node's leg/joint and the POST rule (`arachnae_proto.network.POST`) come
from the generated `arachnae_proto`. The `protocol`, `arbitration` and
`reflexes` sections of spec/nodes.yaml are not in it (yet), so the host builds
this object from the loaded spec and hands it to every behaviour; behaviours never import the spec loader, and never import
the simulator (firmware logic, issue 5).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import arachnae_proto

# What behaviours.runtime implements of the spec's arbitration rules; anything else is refused.
_BACKOFF_SLOT = "request_frame"
_BACKOFF_ORDERS = ("ascending_address", "declared_priority")
_TIMEOUT_TO = ("first_byte", "last_byte")


@dataclass(frozen=True)
class Protocol:
    """nodes.yaml `protocol` (seed 3.2.2, origin: extension), times in seconds."""

    response_timeout_to: str       # 'first_byte': a reply that has STARTED by the timeout is waited for
    master_defer_slots: int        # request slots a master leaves free on an idle line before it sends
    post_report_timeout_s: float   # how long a master waits for a sub-master's POST_REPORT (6.3)
    move_retries: int              # MOVE_RELAYED resends until STATUS_ACK_MMC confirms it
    setpoint_refresh_s: float      # unchanged LEG_TARGET / JOINT_TARGET repeated this often


@dataclass(frozen=True)
class Reflex:
    """nodes.yaml `reflexes` (seed 5.2): records from `source` make `actor` send `command` to `to` at once."""

    source: int
    actor: int
    to: int
    command: str
    min_interval_s: float          # the source raises a reflex request at most this often
    name: str = ""                 # nodes.yaml reflexes.name (the source's debug note names it)


@dataclass(frozen=True)
class NetConfig:
    protocol: Protocol
    arbitration: dict[str, str]            # bus -> 'address_backoff' | 'polled' | 'seed'
    backoff_slots: int                     # spec arbitration.address_backoff: slots per rank step
    backoff_scope: str | None              # 'all' | 'colliders' (who defers after a collision); None: no such rule
    requesters: dict[str, tuple[int, ...]]  # bus -> addresses of the slaves sending its request_message, in rank order
    request_opcodes: dict[str, int]        # bus -> opcode of its request_message (a window slot, not a pause)
    reflexes: tuple["Reflex", ...] = ()    # seed 5.2: fast reactions low in the hierarchy
    reflex_lead_bits: int = 0              # an ordinary request waits this many bit times longer than a reflex one

    def reflex_from(self, source: int) -> "Reflex | None":
        """The reflex whose records come from node `source`, if any."""
        return next((r for r in self.reflexes if r.source == source), None)


    @classmethod
    def from_spec(cls, spec: Any) -> "NetConfig":
        """From a loaded codegen.model.Spec (duck-typed); it must be the spec arachnae_proto was generated from."""
        if spec.hash != arachnae_proto.SPEC_HASH:
            raise ValueError(f"spec {spec.hash[:12]} is not the one arachnae_proto was generated from "
                             f"({arachnae_proto.SPEC_HASH[:12]}); run `arachnae codegen`")
        p = spec.protocol
        if p.response_timeout_to not in _TIMEOUT_TO:
            raise ValueError(f"protocol.response_timeout_to {p.response_timeout_to!r} is not one of {_TIMEOUT_TO}")
        backoff = spec.arbitration.get("address_backoff")
        if backoff and (backoff.get("slot") != _BACKOFF_SLOT or backoff.get("rank_order") not in _BACKOFF_ORDERS):
            raise ValueError(f"arbitration.address_backoff: only slot {_BACKOFF_SLOT} ordered by one of {_BACKOFF_ORDERS} "
                             f"is implemented")
        # spec arbitration (codegen.model.ARBITRATION_DEFAULTS fills what a rule leaves out)
        scope = backoff["backoff_scope"] if backoff else None
        return cls(
            protocol=Protocol(p.response_timeout_to, int(p.master_defer_slots), p.post_report_timeout_ms / 1000,
                              int(p.move_retries), p.setpoint_refresh_ms / 1000),
            arbitration={name: b.arbitration for name, b in spec.buses.items()},
            backoff_slots=int(backoff["backoff_slots"]) if backoff else 0, backoff_scope=scope,
            requesters={name: tuple(n.address for n in spec.requesters(name))
                        for name, b in spec.buses.items() if b.request_message},
            reflexes=tuple(Reflex(spec.node(r.source).address, spec.node(r.actor).address, spec.node(r.to).address,
                                  r.command, r.min_interval_ms / 1000, r.name) for r in spec.reflexes),
            reflex_lead_bits=int(backoff["reflex_lead_bits"]) if backoff else 0,
            request_opcodes={name: spec.message(b.request_message).opcode
                             for name, b in spec.buses.items() if b.request_message},
        )


@dataclass(frozen=True)
class Config:
    """Everything a behaviour is configured with: the network rules, the robot's geometry, the mission."""

    net: NetConfig
    geometry: Any                  # behaviours.geometry.RobotGeometry (or a subclass)
    task: str = "forward"          # NP3 task (docs/decisions.md D8): forward, explore, seek_light, ...
