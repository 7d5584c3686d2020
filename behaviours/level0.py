"""The optional first-level nodes (seed 3.2.6-3.2.9): SSC, APU/SDF, UIC/RCP, RLC.

In the simulation they take part in POST and answer status requests (the
skeleton's common handling, NOT_BUSY); speech, sound direction, the user
interface and the radio link have no simulated hardware yet.
"""
from __future__ import annotations

from arachnae_proto.skeletons.apu_sdf import ApuSdfSkeleton
from arachnae_proto.skeletons.rlc import RlcSkeleton
from arachnae_proto.skeletons.ssc import SscSkeleton
from arachnae_proto.skeletons.uic_rcp import UicRcpSkeleton

from behaviours.runtime import Runtime


class SSC(Runtime, SscSkeleton):
    pass


class APU_SDF(Runtime, ApuSdfSkeleton):
    pass


class UIC_RCP(Runtime, UicRcpSkeleton):
    pass


class RLC(Runtime, RlcSkeleton):
    pass
