"""Frames as bytes, driven entirely by the spec model (codegen.model).

Stand-in for the generated codec `arachnae_proto` (generated/python) until it
exists: the same spec data (header order, field widths, CRC) drives both, and
sim2d only ever calls encode()/decode() here, so switching to the generated
package is a change of this one module.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True)
class Decoded:
    dst: int
    src: int
    name: str
    fields: dict[str, Any]


class Codec:
    def __init__(self, spec: Any):
        self.spec = spec
        self.header = spec.frame.header
        self.crc = spec.frame.checksum
        self.crc_bytes = spec.frame.crc_size
        self._crc_table = self._table()
        # per message: (opcode, fixed bytes, [(name, bits, lo, hi, signed)], array name, count field)
        self._layout: dict[str, tuple] = {}
        for m in spec.messages:
            fields = [(f.name, f.bits, *f.raw_range, f.signed) for f in m.fields if not f.is_array]
            arr = m.array
            self._layout[m.name] = (m.opcode, m.fixed_size, fields, arr.name if arr else None, arr.count if arr else None)
        self._by_opcode = {m.opcode: m.name for m in spec.messages}

    def _table(self) -> list[int]:
        c = self.crc
        if c.refin or c.width != 16:      # only what the table-driven path supports; else use the reference
            return []
        out = []
        for b in range(256):
            crc = b << 8
            for _ in range(8):
                crc = ((crc << 1) ^ c.poly) & 0xFFFF if crc & 0x8000 else (crc << 1) & 0xFFFF
            out.append(crc)
        return out

    def checksum(self, data: bytes) -> int:
        if not self._crc_table:
            return self.crc.compute(data)
        crc, t = self.crc.init, self._crc_table
        for b in data:
            crc = ((crc << 8) & 0xFFFF) ^ t[((crc >> 8) ^ b) & 0xFF]
        return crc ^ self.crc.xorout

    def encode(self, name: str, dst: int, src: int, **raw: Any) -> bytes:
        """Build a frame; field values are raw integers (sim2d.encodings makes them)."""
        opcode, fixed, fields, arr, _ = self._layout[name]
        bits = 0
        for fname, width, lo, hi, _signed in fields:
            v = int(raw.get(fname, 0))
            if not lo <= v <= hi:
                raise ValueError(f"{name}.{fname}={v} outside {lo}..{hi}")
            bits = (bits << width) | (v & ((1 << width) - 1))
        payload = bits.to_bytes(fixed, "big") if fixed else b""
        if arr is not None:
            payload += bytes(raw.get(arr, b""))
        values = {"dst": dst, "src": src, "opcode": opcode, "length": len(payload)}
        body = bytes(values[h] for h in self.header) + payload
        return body + self.checksum(body).to_bytes(self.crc_bytes, "big")

    def decode(self, frame: bytes) -> Decoded | None:
        """The frame's message, or None when it is short, fails the CRC or is not in the spec."""
        hs, cs = len(self.header), self.crc_bytes
        if len(frame) < hs + cs:
            return None
        body, crc = frame[:-cs], int.from_bytes(frame[-cs:], "big")
        if self.checksum(body) != crc:
            return None
        h = dict(zip(self.header, body[:hs]))
        payload = body[hs:]
        if h["length"] != len(payload):
            return None
        name = self._by_opcode.get(h["opcode"])
        if name is None:
            return None
        _, fixed, fields, arr, count = self._layout[name]
        if len(payload) < fixed:
            return None
        value = int.from_bytes(payload[:fixed], "big")
        left = fixed * 8
        out: dict[str, Any] = {}
        for fname, width, lo, hi, signed in fields:
            left -= width
            v = (value >> left) & ((1 << width) - 1)
            if signed and v >= 1 << (width - 1):
                v -= 1 << width
            if not lo <= v <= hi:
                return None          # every codec validates ranges on decode (decision 7)
            out[fname] = v
        if arr is not None:
            if len(payload) != fixed + out[count]:
                return None
            out[arr] = payload[fixed:]
        elif len(payload) != fixed:
            return None
        return Decoded(h["dst"], h["src"], name, out)

    def describe(self, frame: bytes) -> str:
        d = self.decode(frame)
        if d is None:
            return "<undecodable>"
        args = " ".join(f"{k}={v.hex() if isinstance(v, bytes) else v}" for k, v in d.fields.items())
        return f"{d.name} {args}".rstrip()
