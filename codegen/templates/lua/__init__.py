"""Wireshark target (issue 13): a Lua dissector for captures of the buses, `generated/wireshark/arachnae.lua`.

It registers for the spec's user link type (frame.pcap_linktype), decodes the
header (node names), the message and every field (enum names, physical values
with units), checks the CRC and reports each failed check the codecs make
(TRUNCATED, OVERSIZE, CHECKSUM, ROUTE, OPCODE, LENGTH, RANGE) as expert-info errors.
The field walk is table-driven from codegen.layout, shared with the sigrok decoder.
"""
from __future__ import annotations

from codegen.generate import Output
from codegen.layout import views
from codegen.model import ERROR_KINDS, Spec

from . import filters

OUT_DIR = "generated/wireshark"
COMMENT = "--"
FILTERS = filters.FILTERS

# Lua ProtoField constructor of a field, by signedness and width of what holds it
_PROTOFIELD = {(False, 8): "uint8", (True, 8): "int8", (False, 16): "uint16", (True, 16): "int16",
               (False, 32): "uint32", (True, 32): "int32"}


# The codecs' checks a passive reader can make (ADDRESS needs an own address, BUFFER a caller's buffer),
# with the expert-info group each failure belongs to.
EXPERT_GROUPS = {"TRUNCATED": "MALFORMED", "OVERSIZE": "MALFORMED", "CHECKSUM": "CHECKSUM", "ROUTE": "PROTOCOL",
                 "OPCODE": "PROTOCOL", "LENGTH": "MALFORMED", "RANGE": "PROTOCOL"}


def protofield(bits: int, signed: bool) -> str:
    width = 8 if bits <= 8 else 16 if bits <= 16 else 32
    return _PROTOFIELD[(signed, width)]


def outputs(spec: Spec) -> list[Output]:
    expert = [(kind, EXPERT_GROUPS[kind], text) for kind, text in ERROR_KINDS if kind in EXPERT_GROUPS]
    ctx = {"v": views(spec), "protofield": protofield, "c": spec.frame.checksum, "expert": expert}
    return [Output("arachnae.lua", "arachnae.lua.j2", ctx)]
