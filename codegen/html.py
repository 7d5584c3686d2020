"""HTML pages from the spec: the message reference (`arachnae docs`, the seed's 7.3 final report).

Rendered on demand with Jinja2 from codegen/templates/html/ (no plug-in there,
so `arachnae codegen` does not write it): one self-contained page, CSS inline,
the network drawn as inline SVG computed here, no script or font fetched at
view time. Autoescape is on: every string of the spec reaches the page escaped.
sim2d.report renders the run report with the same environment and base page.
"""
from __future__ import annotations

import functools

from collections import defaultdict
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path
from typing import Any, Iterable

import jinja2

from arachnae.files import atomic_open, refuse_foreign
from codegen.encoding import Linear, Log10
from codegen.layout import FieldView, views
from codegen.model import Message, Node, Spec

HTML_TEMPLATES = Path(__file__).resolve().parent / "templates" / "html"


@functools.cache
def environment(*extra_dirs: Path) -> jinja2.Environment:
    """Jinja2 with autoescape on, over `extra_dirs` first and then the shared HTML templates. One per process:
    its templates are compiled once (a batch writes a report.html per run; jinja2 reloads a template changed on disk)."""
    env = jinja2.Environment(loader=jinja2.FileSystemLoader([*map(str, extra_dirs), str(HTML_TEMPLATES)]),
                             autoescape=True, undefined=jinja2.StrictUndefined, trim_blocks=True, lstrip_blocks=True)
    env.filters.update(number=number, hex2=lambda v: f"0x{v:02X}")
    return env


def number(v: Fraction | float | int) -> str:
    """A spec number as a reader writes it: 0.005 or 1/3 (an exact fraction that has no short decimal)."""
    if isinstance(v, Fraction):
        if v.denominator == 1:
            return str(v.numerator)
        dec = f"{float(v):.6g}"
        return dec if Fraction(dec) == v else f"{v.numerator}/{v.denominator}"
    return f"{v:g}" if isinstance(v, float) else str(v)


# -- the network diagram ------------------------------------------------------------------
BOX_W, BOX_H, GAP_X, GAP_Y, STACK_GAP, INDENT, MARGIN = 104, 34, 14, 34, 8, 18, 10


class Box:
    __slots__ = ("node", "x", "y")

    def __init__(self, node: Node, x: float, y: float) -> None:
        self.node, self.x, self.y = node, x, y


@dataclass(frozen=True)
class Wire:
    """A stretch of bus line (bus set) or a drop from a bus to a station (bus empty)."""

    x1: float
    y1: float
    x2: float
    y2: float
    bus: str = ""


@dataclass(frozen=True)
class BusLabel:
    x: float
    y: float
    bus: Any


@dataclass
class Diagram:
    width: float
    height: float
    boxes: list[Box]
    wires: list[Wire]
    labels: list[BusLabel]


def network_diagram(spec: Spec) -> Diagram:
    """Nodes as boxes, each bus as a line below its master: a row when a slave masters a bus itself,
    else a column (the joint controllers under their LCP, the sensors under the SPU)."""
    kids = {n.short: spec.slaves(n.masters) if n.masters else [] for n in spec.nodes}
    size: dict[str, tuple[float, float]] = {}

    def stacked(n: Node) -> bool:
        return all(not kids[k.short] for k in kids[n.short])

    def measure(n: Node) -> tuple[float, float]:
        cs = kids[n.short]
        sizes = [measure(c) for c in cs]
        if not cs:
            wh = (BOX_W, BOX_H)
        elif stacked(n):
            wh = (BOX_W + INDENT, BOX_H + GAP_Y / 2 + len(cs) * (BOX_H + STACK_GAP))
        else:
            wh = (max(BOX_W, sum(w for w, _ in sizes) + GAP_X * (len(cs) - 1)), BOX_H + GAP_Y + max(h for _, h in sizes))
        size[n.short] = wh
        return wh

    d = Diagram(0, 0, [], [], [])

    def place(n: Node, x: float, y: float) -> None:
        w, _ = size[n.short]
        cs = kids[n.short]
        bx = x + (w - BOX_W) / 2 if cs and not stacked(n) else x
        d.boxes.append(Box(n, bx, y))
        if not cs:
            return
        bus = spec.buses[n.masters]  # type: ignore[index]
        top = y + BOX_H
        if stacked(n):
            rail_x = x + INDENT / 2
            last = top + GAP_Y / 2 + (len(cs) - 1) * (BOX_H + STACK_GAP) + BOX_H / 2
            d.wires.append(Wire(rail_x, top, rail_x, last, bus.name))
            d.labels.append(BusLabel(rail_x + 4, top + 11, bus))
            for i, c in enumerate(cs):
                cy = top + GAP_Y / 2 + i * (BOX_H + STACK_GAP)
                d.wires.append(Wire(rail_x, cy + BOX_H / 2, x + INDENT, cy + BOX_H / 2))
                place(c, x + INDENT, cy)
            return
        rail_y = top + GAP_Y / 2
        centres, cx = [], x + (w - (sum(size[c.short][0] for c in cs) + GAP_X * (len(cs) - 1))) / 2
        for c in cs:
            cw = size[c.short][0]
            child_x = cx + (cw - BOX_W) / 2 if kids[c.short] and not stacked(c) else cx
            centres.append(child_x + BOX_W / 2)
            place(c, cx, top + GAP_Y)
            d.wires.append(Wire(child_x + BOX_W / 2, rail_y, child_x + BOX_W / 2, top + GAP_Y))
            cx += cw + GAP_X
        d.wires.append(Wire(bx + BOX_W / 2, top, bx + BOX_W / 2, rail_y))
        d.wires.append(Wire(min(centres + [bx + BOX_W / 2]), rail_y, max(centres + [bx + BOX_W / 2]), rail_y, bus.name))
        d.labels.append(BusLabel(bx + BOX_W / 2 + 4, rail_y - 4, bus))

    roots = [n for n in spec.nodes if n.bus is None]
    x = MARGIN
    height = 0.0
    for r in roots:
        w, h = measure(r)
        place(r, x, MARGIN)
        x += w + GAP_X
        height = max(height, h)
    d.width, d.height = x - GAP_X + MARGIN, height + 2 * MARGIN
    return d


# -- messages -----------------------------------------------------------------------------
@dataclass(frozen=True)
class Route:
    senders: str          # node names
    receivers: str
    buses: str


def routes(spec: Spec, m: Message) -> list[Route]:
    """Who sends the message to whom on which bus, one line per (sender role, receiver role)."""
    grouped: dict[tuple[str, str], tuple[dict, dict, dict]] = defaultdict(lambda: ({}, {}, {}))
    for s, r, bus in spec.routes(m):
        senders, receivers, buses = grouped[(s.role, r.role)]
        senders[s.short] = receivers[r.short] = buses[bus.name] = None
    return [Route(", ".join(a), ", ".join(b), ", ".join(c)) for a, b, c in grouped.values()]


def encoding_text(fv: FieldView) -> str:
    """How raw becomes physical: '' for identity, 'raw × 1/200 + 4', or the log rule."""
    enc = fv.f.encoding
    if isinstance(enc, Log10):
        return (f"raw = {enc.per_decade} × log10(value / {number(enc.ref)})"
                + (", saturating" if enc.saturate else ""))
    assert isinstance(enc, Linear)
    if enc.identity or fv.f.type not in ("uint", "int"):
        return ""
    text = "raw" if enc.scale == 1 else f"raw × {number(enc.scale)}"
    return text + (f" + {number(enc.offset)}" if enc.offset > 0 else f" − {number(-enc.offset)}" if enc.offset < 0 else "")


def values_text(fv: FieldView, spec: Spec) -> str:
    """Valid values: the physical range, enum names, flag bits, or what a node field holds."""
    f = fv.f
    if f.enum is not None:
        return ", ".join(f"{k}={v}" for k, v in f.enum.values.items())
    if f.flags is not None:
        return ", ".join(f"{k}=0x{v:X}" for k, v in f.flags.bits.items())
    if f.type == "node":
        return "a node address"
    if f.type == "char":
        return "characters"
    if f.is_array:
        return f"{f.count} elements, at most {f.count_max}"
    lo, hi = f.raw_range
    raw = f"raw {lo}..{hi}"
    if f.range is not None:
        return f"{number(f.range[0])} .. {number(f.range[1])} {f.unit}".rstrip() + f" ({raw})"
    return raw


def position_text(fv: FieldView) -> str:
    """Byte and bits of the payload, most significant bit first (bit 7 = MSB of a byte)."""
    if fv.f.is_array:
        return f"bytes {fv.byte}.."
    hi_bit = 7 - fv.bit
    lo_bit = hi_bit - fv.f.bits + 1
    if fv.nbytes == 1:
        return f"byte {fv.byte}" if fv.f.bits == 8 else f"byte {fv.byte}, bits {hi_bit}..{lo_bit}"
    return f"bytes {fv.byte}..{fv.byte + fv.nbytes - 1}"


def reference_context(spec: Spec) -> dict[str, Any]:
    v = views(spec)
    return {
        "spec": spec,
        "diagram": network_diagram(spec), "BOX_W": BOX_W, "BOX_H": BOX_H,
        "messages": [{"m": mv.m, "fields": mv.fields, "routes": routes(spec, mv.m)} for mv in v.messages],
        "encoding_text": encoding_text, "values_text": lambda fv: values_text(fv, spec), "position_text": position_text,
        "frame_bytes": lambda m: (spec.frame.overhead + m.min_size, spec.frame.overhead + m.max_size),
    }


def write_page(path: Path, template: str, context: dict[str, Any], extra_dirs: Iterable[Path] = ()) -> Path:
    """Render one page and write it whole (temp file, then rename)."""
    text = environment(*extra_dirs).get_template(template).render(**context)
    with atomic_open(path, "w") as fh:
        fh.write(text)
    return path


GENERATOR_META = '<meta name="generator" content="arachnae">'   # base.html.j2: marks a page as ours


def write_reference(spec: Spec, out_dir: Path, force: bool = False) -> Path:
    """The message reference as out_dir/index.html; an index.html that is not ours is kept unless `force`."""
    page = out_dir / "index.html"
    refuse_foreign(page, GENERATOR_META, "`arachnae docs`", force)
    out_dir.mkdir(parents=True, exist_ok=True)
    return write_page(page, "reference.html.j2", reference_context(spec))
