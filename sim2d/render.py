"""Pictures of a run with Pillow: the world, the path, the final pose, what the sensors saw."""
from __future__ import annotations

from typing import Any

from functools import lru_cache

from PIL import Image, ImageDraw, ImageFont

from sim2d.geometry import to_world


@lru_cache(maxsize=1)
def _font() -> ImageFont.ImageFont:
    """Pillow's bundled scalable font: the bitmap fallback drops the spaces of our captions."""
    return ImageFont.load_default(size=12)

MAX_PX = 900
PATH, SONAR, IR, WHISKER, ROBOT = (0, 120, 255), (160, 0, 160), (255, 120, 0), (220, 0, 0), (30, 90, 200)


class _View:
    def __init__(self, size: tuple[float, float]):
        w, h = size
        self.scale = (MAX_PX - 40) / max(w, h)
        self.w, self.h = int(w * self.scale) + 40, int(h * self.scale) + 40
        self.height_m = h

    def px(self, p: tuple[float, float]) -> tuple[float, float]:
        return (20 + p[0] * self.scale, 20 + (self.height_m - p[1]) * self.scale)


def _world(draw: ImageDraw.ImageDraw, v: _View, sc: Any, step_limit: float) -> None:
    for s in sc.slopes:
        draw.polygon([v.px(p) for p in s.polygon], fill=(225, 235, 250))
    for pit in sc.pits:
        draw.polygon([v.px(p) for p in pit], fill=(40, 40, 40))
    for h in sc.heat:
        r = h.radius * v.scale
        x, y = v.px(h.pos)
        draw.ellipse([x - r, y - r, x + r, y + r], outline=(220, 60, 40), width=2)
    for li in sc.lights:
        x, y = v.px(li.pos)
        draw.ellipse([x - 7, y - 7, x + 7, y + 7], fill=(255, 210, 0), outline=(150, 120, 0))
    for ob in sc.obstacles:
        fill = (150, 150, 150) if ob.height >= step_limit else (205, 205, 205)
        draw.polygon([v.px(p) for p in ob.polygon], fill=fill, outline=(90, 90, 90))
    walls = list(sc.walls)
    if sc.boundary_walls:
        w, h = sc.size
        walls.append(((0, 0), (w, 0), (w, h), (0, h), (0, 0)))
    for line in walls:
        draw.line([v.px(p) for p in line], fill=(0, 0, 0), width=3)


def _robot(draw: ImageDraw.ImageDraw, v: _View, pose: tuple[float, float, float], feet: list, p: Any,
           colour: tuple[int, int, int] = (30, 90, 200)) -> None:
    hl, hw = p.body_length / 2, p.body_width / 2
    corners = [to_world(pose, x, y) for x, y in ((hl, hw), (-hl, hw), (-hl, -hw), (hl, -hw))]
    draw.polygon([v.px(c) for c in corners], outline=colour, fill=(200, 215, 245))
    for leg, foot in zip(p.legs, feet):
        hip = to_world(pose, *p.hip(leg))
        draw.line([v.px(hip), v.px(foot)], fill=colour, width=2)
        x, y = v.px(foot)
        draw.ellipse([x - 2, y - 2, x + 2, y + 2], fill=colour)
    nose = to_world(pose, hl + 0.05, 0)
    draw.line([v.px(to_world(pose, hl, 0)), v.px(nose)], fill=(200, 0, 0), width=2)


def _legend(draw: ImageDraw.ImageDraw, v: _View) -> None:
    x, y = 26, v.h - 16
    for colour, label in ((PATH, "trajectory"), (ROBOT, "final pose"), (SONAR, "sonar returns"),
                          (IR, "IR rays / echoes"), (WHISKER, "whisker contacts")):
        draw.rectangle([x, y, x + 10, y + 8], fill=colour)
        draw.text((x + 14, y - 2), font=_font(), text=label, fill=(0, 0, 0))
        x += 24 + 7 * len(label)


def render_png(result: Any, path: str) -> None:
    """World, trajectory, final pose, sonar returns, IR rays and whisker contacts (issue 4)."""
    sc, robot, log = result.scenario, result.robot, result.sensors.log
    v = _View(sc.size)
    img = Image.new("RGB", (v.w, v.h), (255, 255, 255))
    d = ImageDraw.Draw(img)
    _world(d, v, sc, robot.p.step_limit)
    if sc.expect.reach is not None:
        d.polygon([v.px(p) for p in sc.expect.reach[0]], outline=(0, 160, 0), width=2)
    for _, pt in log.sonar[-4000:]:
        x, y = v.px(pt)
        d.ellipse([x - 1.5, y - 1.5, x + 1.5, y + 1.5], fill=SONAR)
    path_px = [v.px((x, y)) for _, x, y, _ in result.poses]
    if len(path_px) > 1:
        d.line(path_px, fill=PATH, width=2)
    for a, b in log.ir_hits[-2000:]:
        d.line([v.px(a), v.px(b)], fill=IR, width=1)
        x, y = v.px(b)
        d.ellipse([x - 2, y - 2, x + 2, y + 2], fill=IR)
    _robot(d, v, robot.pose, [leg.world for leg in robot.legs.values()], robot.p)
    for a, b, hit in log.ir_rays:                      # the last IR measurement, at the final pose
        d.line([v.px(a), v.px(b)], fill=IR if hit else (255, 190, 140), width=2)
    for _, pt in log.whisker_hits:
        x, y = v.px(pt)
        d.ellipse([x - 4, y - 4, x + 4, y + 4], outline=WHISKER, width=2)
    _legend(d, v)
    m = result.metrics
    d.text((24, 4), font=_font(), text=f"{sc.name} seed {sc.seed}  POST {m['post']['verdict']}  walked {m['distance_walked_m']:.2f} m  "
                    f"collisions {m['collisions']}", fill=(0, 0, 0))
    img.save(path)


def render_gif(result: Any, path: str) -> None:
    sc, robot = result.scenario, result.robot
    v = _View(sc.size)
    base = Image.new("RGB", (v.w, v.h), (255, 255, 255))
    _world(ImageDraw.Draw(base), v, sc, robot.p.step_limit)
    frames = []
    trail: list[tuple[float, float]] = []
    for t, pose, feet in result.frames_png:
        img = base.copy()
        d = ImageDraw.Draw(img)
        trail.append(v.px(pose[:2]))
        if len(trail) > 1:
            d.line(trail, fill=(0, 120, 255), width=2)
        _robot(d, v, pose, feet, robot.p)
        d.text((24, 4), font=_font(), text=f"t = {t:5.1f} s", fill=(0, 0, 0))
        frames.append(img.convert("P", palette=Image.ADAPTIVE, colors=64))
    if frames:
        frames[0].save(path, save_all=True, append_images=frames[1:], duration=100, loop=0, optimize=True)
