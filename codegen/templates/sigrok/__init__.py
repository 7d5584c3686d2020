"""sigrok target (issue 13): a protocol decoder for libsigrokdecode, `generated/sigrok/arachnae/`.

Stacked on sigrok's `uart` decoder, it cuts the bytes of one RS-485 line into
frames at the bus's idle gap, checks them like the codecs (size by the length
byte, CRC, route as a codec without an own address, opcode, payload length, field ranges) and annotates every header
field and message field at its bytes, or at its bits when it shares a byte.
It is plain Python for the sigrok interpreter: no arachnae package needed,
only the tables below (codegen.layout, shared with the Wireshark dissector).
"""
from __future__ import annotations

from codegen.generate import Output
from codegen.layout import views
from codegen.model import Spec

OUT_DIR = "generated/sigrok/arachnae"
COMMENT = "#"
FILTERS = {"pyrepr": repr}


def outputs(spec: Spec) -> list[Output]:
    ctx = {"v": views(spec), "c": spec.frame.checksum}
    return [Output("__init__.py", "init.py.j2", ctx), Output("pd.py", "pd.py.j2", ctx)]
