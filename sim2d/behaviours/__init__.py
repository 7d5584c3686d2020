"""Hand-written behaviour of every node role; ROLES maps the spec's role to its class."""
from __future__ import annotations

from sim2d.behaviours.base import NodeProcess
from sim2d.behaviours.jac import JAC
from sim2d.behaviours.lcp import LCP
from sim2d.behaviours.mcp import MCP
from sim2d.behaviours.mmc import MMC
from sim2d.behaviours.np3 import NP3
from sim2d.behaviours.sensor_nodes import IRRC, ISC, LSC, PSC, TPSC, TSC, USRC
from sim2d.behaviours.spu import SPU

# SSC, APU/SDF, UIC/RCP and RLC only take part in POST and status here (generic handlers).
ROLES: dict[str, type[NodeProcess]] = {
    "MCP": MCP, "NP3": NP3, "MMC": MMC, "SPU": SPU, "LCP": LCP, "JAC": JAC,
    "USRC": USRC, "TPSC": TPSC, "IRRC": IRRC, "ISC": ISC, "TSC": TSC, "LSC": LSC, "PSC": PSC,
}


def behaviour(role: str) -> type[NodeProcess]:
    return ROLES.get(role, NodeProcess)
