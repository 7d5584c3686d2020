"""report.html of a run: one offline page with the world, a replay slider, the control, the buses and the metrics.

Written by every `sim run` beside its other outputs (sim2d.runner). Everything
is inline: SVG drawn from the scenario and the pose log, the run's PNGs as
data: URIs, the poses as JSON for a small script that moves the robot along
the time slider. Rendered with codegen.html's Jinja2 environment (autoescape on).
It must stay cheap: it runs on every simulation.
"""
from __future__ import annotations

import base64
import csv
import json
import math
from bisect import bisect_left, bisect_right
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from behaviours.subsumption import Interval
from captures.decode import decode
from codegen.html import write_page

TEMPLATES = Path(__file__).resolve().parent / "templates"
WORLD_PX = 760            # the longer side of the arena on the page
LOAD_BINS = 120           # time bins of the bus load charts
MAX_POSES = 2000          # pose samples handed to the slider script
SEQ_MARGIN_S = 0.05       # the sequence chart shows this much before the stimulus and after the MOVE
SEQ_MAX_FRAMES = 60


@dataclass(frozen=True)
class World:
    """The arena in page coordinates (y down): every shape as an SVG points string."""

    width: float
    height: float
    scale: float
    walls: list[str]
    pits: list[str]
    slopes: list[tuple[str, str]]              # points, "10° along x"
    obstacles: list[tuple[str, float, str]]    # points, height m, fill
    lights: list[tuple[float, float, float]]   # x, y, intensity
    heat: list[tuple[float, float, float, float]]   # x, y, radius px, temperature
    regions: list[tuple[str, str]]             # points, "goal" | "forbidden"
    path: str
    start: tuple[float, float]
    body: tuple[float, float]                  # the robot's length and width in px


def _obstacle_fill(height: float, step_limit: float) -> str:
    """Grey by height: light for what the legs step over, darker the higher it is (seed 1.2.1)."""
    if height < step_limit:
        return "#d2d2d2"
    shade = max(70, 160 - int(400 * (height - step_limit)))
    return f"rgb({shade},{shade},{shade})"


def world_view(result: Any) -> World:
    sc = result.scenario
    w, h = sc.size
    k = WORLD_PX / max(w, h)

    def pt(p) -> tuple[float, float]:
        return round(p[0] * k, 1), round((h - p[1]) * k, 1)

    def pts(poly) -> str:
        return " ".join(f"{x},{y}" for x, y in map(pt, poly))

    walls = [pts(line) for line in sc.walls]
    if sc.boundary_walls:
        walls.append(pts(((0, 0), (w, 0), (w, h), (0, h), (0, 0))))
    step_limit = result.robot.p.step_limit
    regions = []
    if sc.expect.reach is not None:
        regions.append((pts(sc.expect.reach[0]), "goal"))
    if sc.expect.stay_out is not None:
        regions.append((pts(sc.expect.stay_out), "forbidden"))
    slopes = []
    for s in sc.slopes:
        along = [f"{a:g}° along {axis}" for a, axis in ((s.incline_x, "x"), (s.incline_y, "y")) if a]
        slopes.append((pts(s.polygon), ", ".join(along)))
    return World(
        round(w * k, 1), round(h * k, 1), k, walls, [pts(p) for p in sc.pits], slopes,
        [(pts(o.polygon), o.height, _obstacle_fill(o.height, step_limit)) for o in sc.obstacles],
        [(*pt(li.pos), li.intensity) for li in sc.lights],
        [(*pt(ht.pos), round(ht.radius * k, 1), ht.temperature) for ht in sc.heat],
        regions, pts((x, y) for _, x, y, _ in result.poses), pt(sc.start[:2]),
        (round(result.robot.p.body_length * k, 1), round(result.robot.p.body_width * k, 1)))


def legend(result: Any) -> list[tuple[str, str]]:
    """(fill, label) of every kind of thing the world holds; obstacles by height."""
    sc = result.scenario
    step_limit = result.robot.p.step_limit
    out = [("#0078ff", "trajectory")]
    if sc.pits:
        out.append(("#282828", "pit"))
    if sc.slopes:
        out.append(("#e1ebfa", "slope"))
    for height in sorted({o.height for o in sc.obstacles}):
        kind = "stepped over" if height < step_limit else "too high to step over"
        out.append((_obstacle_fill(height, step_limit), f"obstacle {height:g} m ({kind})"))
    if sc.lights:
        out.append(("#ffd200", "light"))
    if sc.heat:
        out.append(("#ffffff", "heat source (ring: 1/e radius)"))
    return out


def poses_json(result: Any) -> list[list[float]]:
    """[t, x, y, heading°] per sample, at most MAX_POSES, in page coordinates."""
    sc = result.scenario
    k = WORLD_PX / max(sc.size)
    poses = result.poses
    step = max(1, math.ceil(len(poses) / MAX_POSES))
    return [[round(t, 2), round(x * k, 1), round((sc.size[1] - y) * k, 1), round(math.degrees(th), 1)]
            for t, x, y, th in poses[::step]]


# -- control and buses ---------------------------------------------------------------------
def control_intervals(folder: Path) -> list[Interval]:
    """The subsumption control trace the NP3 wrote (control.tsv, behaviours.subsumption intervals), if any."""
    path = folder / "control.tsv"
    if not path.is_file():
        return []
    with open(path, newline="") as fh:
        return [Interval(float(r["start_s"]), float(r["end_s"]), r["layer"], r["module"])
                for r in csv.DictReader(fh, delimiter="\t")]


def bus_load(frames: list[Any], buses: list[str], duration: float) -> dict[str, list[float]]:
    """Share of each time bin the line was busy, per bus: the union of the frames' [start, end) intervals,
    so two colliding frames count once (as the line's busy time in metrics.json does)."""
    width = duration / LOAD_BINS
    spans: dict[str, list[tuple[float, float]]] = {b: [] for b in buses}
    for f in sorted(frames, key=lambda f: f.start):
        merged = spans.get(f.bus)
        if merged is None:
            continue
        start, end = f.start, min(f.end, duration)
        if merged and start <= merged[-1][1]:
            merged[-1] = (merged[-1][0], max(merged[-1][1], end))
        else:
            merged.append((start, end))
    load = {b: [0.0] * LOAD_BINS for b in buses}
    for bus, merged in spans.items():
        bins = load[bus]
        for start, end in merged:
            for i in range(int(start / width), min(int(end / width), LOAD_BINS - 1) + 1):
                bins[i] += max(0.0, min(end, (i + 1) * width) - max(start, i * width))
    return {b: [round(min(v / width, 1.0), 4) for v in bins] for b, bins in load.items()}


@dataclass(frozen=True)
class Arrow:
    time: float
    bus: str
    src: str
    dst: str
    label: str
    ok: bool


@dataclass(frozen=True)
class Sequence:
    reaction: dict[str, Any]
    lifelines: list[str]
    arrows: list[Arrow]
    more: int                     # frames in the window not drawn (beyond SEQ_MAX_FRAMES)

    def row_of(self, t: float) -> int:
        """How many drawn frames start before t: where a marker at t goes."""
        return bisect_left([a.time for a in self.arrows], t)


def sequences(frames: list[Any], reactions: list[dict[str, Any]], spec: Any) -> list[Sequence]:
    """The bus traffic around each reaction (seed 5.2) on the buses where slaves report events on their
    own (a request message: the MCP's bus and the sensor bus), the path from a stimulus to MOVE."""
    buses = {b.name for b in spec.buses.values() if b.request_message}
    starts = [f.start for f in frames]
    order = {n.short: n.address for n in spec.nodes}
    out = []
    for r in reactions:
        lo = bisect_left(starts, r["stimulus_s"] - SEQ_MARGIN_S)
        hi = bisect_right(starts, r["move_s"] + SEQ_MARGIN_S)
        window = [f for f in frames[lo:hi] if f.bus in buses]
        arrows = []
        for f in window[:SEQ_MAX_FRAMES]:
            d = decode(f.heard if f.heard is not None else f.sent)
            ok = d.message is not None and f.heard is not None
            src = d.src if d.message is not None else f.sender
            dst = d.dst if d.message is not None else "?"
            label = d.name + ("" if f.heard is not None else " (lost)")
            arrows.append(Arrow(f.start, f.bus, src, dst, label, ok))
        names = {a.src for a in arrows} | {a.dst for a in arrows}
        lifelines = sorted(names, key=lambda n: (order.get(n, 0x100 if n == "ALL" else 0x101), n))
        out.append(Sequence(r, lifelines, arrows, max(0, len(window) - SEQ_MAX_FRAMES)))
    return out


# (label, dotted metric path, unit) of the figures the report lists first (sim2d.metrics names)
KEY_METRICS = (
    ("POST verdict", "post.verdict", ""), ("POST done at", "post.time_s", "s"),
    ("distance walked", "distance_walked_m", "m"), ("displacement", "displacement_m", "m"),
    ("final pose (x, y, heading°)", "final_pose", ""), ("collisions", "collisions", ""),
    ("least clearance", "min_clearance_m", "m"), ("pit events", "pit_events", ""), ("fell", "fell", ""),
    ("tilt events", "tilt_events", ""), ("largest tilt", "max_tilt_deg", "°"), ("goal reached at", "reach_time_s", "s"),
    ("MOVE commands", "moves", ""), ("slowest reaction", "max_reaction_s", "s"), ("frames", "frames", ""),
    ("frames lost", "frame_loss", ""), ("frames corrupted", "frames_corrupted", ""),
    # seed 3.2.17, issue 18: the battery under load, what the PSC judged against its limit, and the stalls behind a dip
    ("battery lowest (under load)", "battery.v_min", "V"), ("battery open-circuit at the end", "battery.emf_final_v", "V"),
    ("PSC mean, lowest", "battery.psc_mean_min_v", "V"), ("PSC level judged, lowest", "battery.psc_level_min_v", "V"),
    ("PSC alarms", "battery.psc_alarms", ""), ("servo stall, longest", "battery.stall_longest_s", "s"),
)


def key_metrics(m: dict[str, Any]) -> list[tuple[str, str]]:
    from sim2d.metrics import lookup

    out = []
    for label, path, unit in KEY_METRICS:
        v = lookup(m, path)
        if isinstance(v, float):
            v = round(v, 3)
        out.append((label, "—" if v is None else f"{v} {unit}".rstrip()))
    return out


def data_uri(path: Path) -> str | None:
    return "data:image/png;base64," + base64.b64encode(path.read_bytes()).decode() if path.is_file() else None


def write_report(outcome: Any, folder: Path) -> Path:
    """folder/report.html from the outcome and the outputs already in folder (control.tsv, PNGs)."""
    r = outcome.result
    spec = outcome.spec
    m = r.metrics
    duration = outcome.scenario.duration
    frames = sorted(r.frames, key=lambda f: f.start)
    ctx = {
        "sc": outcome.scenario, "m": m, "spec": spec, "expectations": outcome.expectations,
        "key_metrics": key_metrics(m), "metrics_json": json.dumps(m, indent=1),
        "world": world_view(r), "legend": legend(r), "poses": poses_json(r), "duration": duration,
        "control": control_intervals(folder),
        "load": bus_load(frames, list(spec.buses), duration), "load_bin_s": duration / LOAD_BINS,
        "seq_margin_ms": round(SEQ_MARGIN_S * 1000),
        "sequences": sequences(frames, m.get("reactions", []), spec),
        "pictures": [(name, uri) for name, uri in (("run.png", data_uri(folder / "run.png")),
                                                   ("topomap.png", data_uri(folder / "topomap.png"))) if uri],
    }
    return write_page(folder / "report.html", "report.html.j2", ctx, extra_dirs=[TEMPLATES])
