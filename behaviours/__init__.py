"""Hand-written node behaviours: the firmware logic of every ARACHNAE II role.

Each class subclasses its generated skeleton (arachnae_proto.skeletons) and
overrides the typed `on_<message>` hooks; frames leave through the
skeleton's transport, the board is reached through behaviours.hardware.
Nothing here imports the simulator: the same classes would run on a host
with serial ports and real sensors (issue 5).

    cls = behaviour_class("MMC")
    node = cls(address, transmit, hw, cfg)   # transmit(bus, frame_bytes); hw: Hardware; cfg: Config
    node.start()                             # power-on
    node.receive(bus, frame_bytes)           # a frame heard on one of its buses
    node.on_echo(bus, sent, heard)           # its own frame read back by the transceiver
"""
from __future__ import annotations

from behaviours.jac import JAC
from behaviours.lcp import LCP
from behaviours.level0 import APU_SDF, RLC, SSC, UIC_RCP
from behaviours.mcp import MCP
from behaviours.mmc import MMC
from behaviours.np3 import NP3
from behaviours.runtime import Runtime
from behaviours.sensors import IRRC, ISC, LSC, PSC, TPSC, TSC, USRC
from behaviours.spu import SPU

ROLES: dict[str, type[Runtime]] = {
    "MCP": MCP, "NP3": NP3, "MMC": MMC, "SPU": SPU, "SSC": SSC, "APU_SDF": APU_SDF, "UIC_RCP": UIC_RCP, "RLC": RLC,
    "LCP": LCP, "JAC": JAC, "USRC": USRC, "TPSC": TPSC, "IRRC": IRRC, "ISC": ISC, "TSC": TSC, "LSC": LSC, "PSC": PSC,
}


def behaviour_class(role: str) -> type[Runtime]:
    """The behaviour of a spec role (KeyError for a role without one)."""
    return ROLES[role]
