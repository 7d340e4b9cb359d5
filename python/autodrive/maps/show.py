"""Draws a map from above as a PNG (tools/map show): the tiles with their textures, free-form
roads and their markings, terrain patches, walls, boxes, cones, parking slots, lane centre lines with arrows, stop
lines, traffic lights, signs and spawns, all from the description."""

from __future__ import annotations

import io
import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import numpy.typing as npt  # noqa: E402
from matplotlib.patches import Polygon, Rectangle  # noqa: E402
from PIL import Image  # noqa: E402

from autodrive.maps import textures  # noqa: E402
from autodrive.maps.description import MapDescription  # noqa: E402
from autodrive.maps.loader import MAPS_DIR  # noqa: E402
from autodrive.maps.model import rect_corners  # noqa: E402
from autodrive.maps.tiles import TileContent  # noqa: E402

LIGHT_COLOUR = "#d62728"
SIGN_COLOUR = "#1f77b4"
SPAWN_COLOUR = "#9467bd"


def _texture(m: MapDescription, tile: TileContent, maps_dir: Path) -> npt.NDArray[np.uint8]:
    """A tile's texture: the generated file, or painted now (a map not yet generated)."""
    path = maps_dir / textures.DIR_NAME / f"{tile.texture}.png"
    if path.is_file():
        data = path.read_bytes()
    else:
        key = (tile.spec.type, tile.spec.lanes)
        data = textures.generate(m.kit, {key}, set())[tile.texture]
    return np.asarray(Image.open(io.BytesIO(data)).convert("RGB"))


def draw(m: MapDescription, out: Path, maps_dir: Path = MAPS_DIR, dpi: int = 110) -> None:
    """Writes the map's top view to out (PNG); tile textures are read from maps_dir."""
    kit = m.kit
    h = m.floor_half_size_m
    fig, ax = plt.subplots(figsize=(10, 10))
    floor = kit.surfaces[m.floor_surface].rgba
    ax.add_patch(Rectangle((-h, -h), 2 * h, 2 * h, color=floor[:3], zorder=0))
    for t in m.tile_contents():
        img = np.rot90(_texture(m, t, maps_dir), k=round(t.spec.rotation_deg / 90) % 4)
        cx, cy = t.spec.centre_m
        s = t.size_m / 2
        ax.imshow(img, extent=(cx - s, cx + s, cy - s, cy + s), zorder=1, interpolation="nearest")
        ax.add_patch(Rectangle((cx - s, cy - s), 2 * s, 2 * s, fill=False, lw=0.3, ec="k",
                               zorder=2))  # fmt: skip
    for r in m.roads:  # free-form roads: their tarmac as a thick line
        pts = m.centre_line(r.lanes[0].name) if r.lanes else []
        if pts:
            ax.plot([p[0] for p in pts], [p[1] for p in pts], color=kit.road.rgba[:3],
                    lw=r.width_m * 72 * 10 / (2 * h) * 0.9, zorder=1, solid_capstyle="butt")  # fmt: skip
    for mk in m.markings:  # painted lines at their width
        colour = kit.marking.yellow_rgba if mk.colour == "yellow" else kit.marking.rgba
        for st in mk.strokes:
            ax.plot([p[0] for p in st], [p[1] for p in st], color=colour[:3],
                    lw=mk.width_m * 72 * 10 / (2 * h) * 0.9, zorder=1, solid_capstyle="butt")  # fmt: skip
    for p in m.terrain_patches:
        c = rect_corners(p.centre_m, p.size_m, 0.0)
        ax.add_patch(Polygon(c, color=kit.surfaces[p.surface].rgba[:3], zorder=2))
        ax.text(*p.centre_m, p.surface, ha="center", va="center", fontsize=6, zorder=6)
    for w in m.walls:
        nx, ny = w.normal
        x, y = w.face_centre_m
        dx, dy = -ny * w.length_m / 2, nx * w.length_m / 2
        ax.plot([x - dx, x + dx], [y - dy, y + dy], color="0.4", lw=3, zorder=3)
    for slot in m.slots():
        c = slot.corners_m()
        ax.add_patch(Polygon(c, fill=False, ec="w", lw=0.6, zorder=3))
    for b in m.obstacles():
        c = rect_corners((b.x_m, b.y_m), (2 * b.half_x_m, 2 * b.half_y_m), b.yaw_rad)
        ax.add_patch(Polygon(c, color=kit.obstacle.box_rgba[:3], zorder=4))
    for o in m.late_obstacles:
        c = rect_corners(o.centre_m, o.size_m[:2], o.yaw_rad)
        ax.add_patch(Polygon(c, fill=False, ec=kit.obstacle.box_rgba[:3], ls="--", zorder=4))
    for lane in m.lanes():
        pts = m.centre_line(lane)
        xs, ys = [p[0] for p in pts], [p[1] for p in pts]
        ax.plot(xs, ys, color="#2ca02c", lw=0.7, zorder=5)
        k = len(pts) // 2
        x, y, yaw = pts[k]
        ax.annotate("", xy=(x + 0.06 * math.cos(yaw), y + 0.06 * math.sin(yaw)), xytext=(x, y),
                    arrowprops=dict(arrowstyle="-|>", color="#2ca02c", lw=0.7), zorder=5)  # fmt: skip
    for stop in m.all_stop_lines():
        yaw = m.stop_line_yaw_rad(stop)
        dx, dy = math.cos(yaw) * stop.length_m / 2, math.sin(yaw) * stop.length_m / 2
        x, y = stop.centre_m
        ax.plot([x - dx, x + dx], [y - dy, y + dy], color="#ff7f0e", lw=2, zorder=6)
    for light in m.lights():
        x, y = light.position_m
        ax.plot(x, y, "o", color=LIGHT_COLOUR, ms=5, zorder=7)
        ax.annotate("", xy=(x + 0.15 * math.cos(light.yaw_rad), y + 0.15 * math.sin(light.yaw_rad)),
                    xytext=(x, y), arrowprops=dict(arrowstyle="-|>", color=LIGHT_COLOUR), zorder=7)  # fmt: skip
        ax.text(x, y + 0.1, light.name, color=LIGHT_COLOUR, fontsize=6, ha="center", zorder=7)
    for sign in m.placed_signs():
        x, y = sign.position_m
        ax.plot(x, y, "s", color=SIGN_COLOUR, ms=4, zorder=7)
        label = sign.kind + (f" {sign.speed_limit_m_s:g}" if sign.speed_limit_m_s else "")
        ax.text(x, y - 0.16, label, color=SIGN_COLOUR, fontsize=6, ha="center", zorder=7)
    spawns = [("spawn", m.spawn_pose())] + [(s.name, s.pose) for s in m.named_spawns()]
    for name, sp in spawns:
        ax.annotate("", xy=(sp.x_m + 0.25 * math.cos(sp.yaw_rad), sp.y_m + 0.25 * math.sin(sp.yaw_rad)),
                    xytext=(sp.x_m, sp.y_m), arrowprops=dict(arrowstyle="-|>", color=SPAWN_COLOUR,
                                                           lw=1.5), zorder=8)  # fmt: skip
        ax.text(sp.x_m, sp.y_m - 0.12, name, color=SPAWN_COLOUR, fontsize=6, ha="center", zorder=8)
    ax.set_xlim(-h, h)
    ax.set_ylim(-h, h)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m] (east)")
    ax.set_ylabel("y [m] (north)")
    ax.set_title(
        f"{m.name}: {len(m.tiles)} tiles, {len(m.lanes())} lanes, {len(m.lights())} lights, "
        f"{len(m.signs)} signs, {len(m.named_routes())} routes, {len(m.slots())} slots\n"
        "green: lane centre lines; orange: stop lines; red: lights; blue: signs; purple: spawns",
        fontsize=9,
    )
    fig.tight_layout()
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=dpi)
    plt.close(fig)
