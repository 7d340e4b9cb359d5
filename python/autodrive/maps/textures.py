"""Paints the road kit's textures (maps/textures/*.png): one per tile type and
lane count, one per sign kind. Deterministic (numpy masks, fixed PNG settings) so that
tools/gen-maps --check can compare bytes. A tile texture is its square seen from above,
unrotated (image up = the tile's +y, image right = +x); stop lines and slot lines come from the
same shapes the description's tiles expand into (tiles.py)."""

from __future__ import annotations

import io
import math
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np
import numpy.typing as npt
from PIL import Image, ImageDraw

from autodrive.maps import tiles
from autodrive.maps.model import Kit, Lane, SignKindKit, TileKit, TileSpec, Vec2, Vec3

DIR_NAME = "textures"
Mask = npt.NDArray[np.bool_]  # a boolean image
Array = npt.NDArray[Any]  # an image or a field of distances [m]

# 3 x 5 pixel glyphs for sign texts (no font files: the same bytes on every machine)
GLYPHS = {
    "S": ["111", "100", "111", "001", "111"],
    "T": ["111", "010", "010", "010", "010"],
    "O": ["111", "101", "101", "101", "111"],
    "P": ["111", "101", "111", "100", "100"],
    "0": ["111", "101", "101", "101", "111"],
    "1": ["010", "110", "010", "010", "111"],
    "2": ["111", "001", "111", "100", "111"],
    "3": ["111", "001", "111", "001", "111"],
    "4": ["101", "101", "111", "001", "001"],
    "5": ["111", "100", "111", "001", "111"],
    "6": ["111", "100", "111", "101", "111"],
    "7": ["111", "001", "010", "010", "010"],
    "8": ["111", "101", "111", "101", "111"],
    "9": ["111", "101", "111", "001", "111"],
}


def png_bytes(img: Image.Image) -> bytes:
    buf = io.BytesIO()
    img.save(buf, format="PNG", compress_level=9, optimize=False)
    return buf.getvalue()


def sign_texture_name(kind: str, speed_limit_m_s: float | None = None) -> str:
    """One texture per sign kind; a speed limit's shows its number [cm/s]."""
    if kind == "speed_limit" and speed_limit_m_s is not None:
        return f"sign_{kind}_{round(speed_limit_m_s * 100)}"
    return f"sign_{kind}"


@dataclass(frozen=True)
class Marking:
    """How a tile's centre line and edge lines are painted and its road surface coloured. The
    default is the kit's own (its centre_rgb dashed, its line_rgb solid edges, its asphalt);
    other values are domain-randomisation variants (autodrive.maps.road_styles). Lane dividers,
    stop lines, slot lines, a corner's curb and a closed side keep the kit's look."""

    centre_rgb: Vec3 | None = None  # None: the kit's centre_rgb
    centre_dashed: bool = True
    edge_rgb: Vec3 | None = None  # None: the kit's line_rgb
    edge_dashed: bool = False
    asphalt_rgb: Vec3 | None = None  # None: the kit's asphalt_rgb


KIT_MARKING = Marking()


# --- tiles --------------------------------------------------------------------------------------


class _Canvas:
    """A tile's pixel grid with the local coordinates of each pixel centre."""

    def __init__(self, kit: TileKit, size_m: float) -> None:
        self.kit = kit
        self.n = max(8, round(size_m * kit.texture_px_per_m))
        h = size_m / 2
        c = (np.arange(self.n) + 0.5) / self.n * size_m - h
        self.x, self.y = np.meshgrid(c, -c)  # row 0 is the top (+y)
        self.rgb = np.zeros((self.n, self.n, 3), np.uint8)
        self.rgb[:] = kit.verge_rgb

    def paint(self, mask: Mask, rgb: tuple[float, float, float]) -> None:
        self.rgb[mask] = rgb

    def seg(self, a: Vec2, b: Vec2) -> Array:
        """Distance of every pixel from the segment a-b [m]."""
        ax, ay = b[0] - a[0], b[1] - a[1]
        den = ax * ax + ay * ay
        t = np.clip(((self.x - a[0]) * ax + (self.y - a[1]) * ay) / den, 0, 1)
        return np.asarray(np.hypot(a[0] + t * ax - self.x, a[1] + t * ay - self.y))

    def along(self, a: Vec2, b: Vec2) -> Array:
        """Distance along a-b from a of each pixel's projection [m] (for dashes)."""
        ln = math.dist(a, b)
        return np.asarray(((self.x - a[0]) * (b[0] - a[0]) + (self.y - a[1]) * (b[1] - a[1])) / ln)

    def arc(self, centre: Vec2, r: float, a0: float, sweep: float) -> Array:
        """Distance of every pixel from a circular arc (angles in rad, sweep may be < 0)."""
        lo, hi = (a0, a0 + sweep) if sweep > 0 else (a0 + sweep, a0)
        dx, dy = self.x - centre[0], self.y - centre[1]
        ang = np.arctan2(dy, dx)
        rel = np.mod(ang - lo, 2 * math.pi)
        inside = rel <= hi - lo
        radial = np.abs(np.hypot(dx, dy) - r)
        ends = [(centre[0] + r * math.cos(a), centre[1] + r * math.sin(a)) for a in (lo, hi)]
        d_end = np.minimum(*[np.hypot(self.x - e[0], self.y - e[1]) for e in ends])
        return np.asarray(np.where(inside, radial, d_end))

    def png(self) -> bytes:
        return png_bytes(Image.fromarray(self.rgb, "RGB"))


def _lane_prims(lane: Lane) -> list[tuple[str, tuple[float, ...]]]:
    out: list[tuple[str, tuple[float, ...]]] = []
    for p in lane.road.pieces:
        if p.line is not None:
            out.append(("seg", (*p.line.from_m, *p.line.to_m)))
        else:
            assert p.arc is not None
            a = p.arc
            out.append(("arc", (*a.centre_m, a.radius_m, math.radians(a.start_deg),
                                math.radians(a.sweep_deg))))  # fmt: skip
    return out


def _dist(cv: _Canvas, prims: list[tuple[str, tuple[float, ...]]], offset_m: float) -> Array:
    """Distance from a lane's centre line moved offset_m to its left (arcs change radius)."""
    d = np.full(cv.x.shape, np.inf)
    for kind, v in prims:
        if kind == "seg":
            x0, y0, x1, y1 = v
            ln = math.hypot(x1 - x0, y1 - y0)
            nx, ny = -(y1 - y0) / ln, (x1 - x0) / ln
            a = (x0 + offset_m * nx, y0 + offset_m * ny)
            b = (x1 + offset_m * nx, y1 + offset_m * ny)
            d = np.minimum(d, cv.seg(a, b))
        else:
            cx, cy, r, a0, sw = v
            rr = r - offset_m * math.copysign(1.0, sw)
            d = np.minimum(d, cv.arc((cx, cy), rr, a0, sw))
    return d


def _dashes(cv: _Canvas, prims: list[tuple[str, tuple[float, ...]]], offset_m: float) -> Mask:
    """Pixels on the dash pattern along a lane's pieces (arc length from each piece's start)."""
    k = cv.kit
    pitch = k.dash_length_m + k.dash_gap_m
    on = np.zeros(cv.x.shape, bool)
    for kind, v in prims:
        if kind == "seg":
            s = cv.along((v[0], v[1]), (v[2], v[3]))
        else:
            cx, cy, r, a0, sw = v
            rr = r - offset_m * math.copysign(1.0, sw)
            ang = np.arctan2(cv.y - cy, cv.x - cx)
            s = np.mod((ang - a0) * math.copysign(1.0, sw), 2 * math.pi) * rr
        on |= (np.mod(s, pitch) < k.dash_length_m) & (_dist(cv, [(kind, v)], offset_m) < 1)
    return on


def _tile_png(kit: Kit, tile_type: str, lanes: int, marking: Marking = KIT_MARKING) -> bytes:
    tk = kit.tiles
    spec = TileSpec(name="t", type=tile_type, lanes=lanes, centre_m=(0.0, 0.0))  # type: ignore[arg-type]
    content = tiles.expand(tk, spec)
    cv = _Canvas(tk, content.size_m)
    asphalt = marking.asphalt_rgb or tk.asphalt_rgb
    if tile_type == "patch":
        cv.rgb[:] = asphalt
        return cv.png()
    w, half_w = tk.lane_width_m, content.road_width_m / 2
    lw = tk.paint_width_m / 2
    edge_off = tk.shoulder_m / 2  # edge lines this far inside the road's edge
    offsets = tiles.lane_offsets_m(tk, lanes)
    k = len(offsets)
    inner, outer = offsets[0], offsets[-1]
    h = content.size_m / 2
    box = tiles.cell_m(tk, lanes) / 2
    arms = [tiles.SIDES.index(a) for a in tiles.ARMS[tile_type]]
    units = {
        i: (round(math.cos(i * math.pi / 2)), round(math.sin(i * math.pi / 2))) for i in range(4)
    }
    road = np.zeros(cv.x.shape, bool)
    white = np.zeros(cv.x.shape, bool)
    yellow = np.zeros(cv.x.shape, bool)  # the centre line where it is drawn in full
    centre_on = np.zeros(cv.x.shape, bool)  # the dash pattern along the centre line
    edge = np.zeros(cv.x.shape, bool)  # the edge lines (of the arms and lanes) in full
    edge_on = np.ones(cv.x.shape, bool)  # the dash pattern along them (all on: no pattern)
    pitch_m = tk.dash_length_m + tk.dash_gap_m
    by_name = {lane.name: lane for lane in content.lanes}

    def approach(i: int, from_m: float) -> tuple[Vec2, Vec2, Callable[[float], tuple[Vec2, Vec2]]]:
        """An arm's axis from the tile edge to from_m from the centre, and its offset copies."""
        u = units[i]
        a, b = (h * u[0], h * u[1]), (from_m * u[0], from_m * u[1])
        v = (-u[1], u[0])

        def off(o: float) -> tuple[Vec2, Vec2]:
            return (a[0] + o * v[0], a[1] + o * v[1]), (b[0] + o * v[0], b[1] + o * v[1])

        return a, b, off

    def mark_axis(i: int, to_m: float) -> None:
        """Edge lines, the centre line and lane dividers of an arm from the edge to to_m."""
        a, b, off = approach(i, to_m)
        road[cv.seg(a, b) <= half_w] = True
        for s in (-1, 1):
            ea, eb = off(s * (half_w - edge_off))
            near = cv.seg(ea, eb) <= lw
            edge[near] = True
            edge_on[near] = np.mod(cv.along(ea, eb), pitch_m)[near] < tk.dash_length_m
            for d in offsets[1:]:
                pa, pb = off(s * (d - w / 2))
                white[(cv.seg(pa, pb) <= lw) & (np.mod(cv.along(pa, pb), tk.dash_length_m + tk.dash_gap_m) < tk.dash_length_m)] = True  # fmt: skip
        if lanes == 2:
            pa, pb = off(0.0)
            near = cv.seg(pa, pb) <= lw
            yellow[near] = True
            centre_on[near & (np.mod(cv.along(pa, pb), pitch_m) < tk.dash_length_m)] = True
        elif lanes > 2:
            for s in (-1, 1):
                yellow[cv.seg(*off(s * 1.5 * tk.paint_width_m)) <= lw] = True

    if tile_type in ("tee", "cross"):
        for i in arms:
            mark_axis(i, box)
        inside = (np.abs(cv.x) <= box) & (np.abs(cv.y) <= box)
        rc = box - half_w  # curb radius at a corner between two arms
        surface = inside.copy()
        for i in range(4):
            j = (i + 1) % 4
            ui, uj = units[i], units[j]
            corner = (box * (ui[0] + uj[0]), box * (ui[1] + uj[1]))
            if i in arms and j in arms:
                surface &= np.hypot(cv.x - corner[0], cv.y - corner[1]) >= rc
                a0 = math.atan2(-ui[1] - uj[1], -ui[0] - uj[0]) - math.pi / 4
                white[cv.arc(corner, rc + edge_off, a0, math.pi / 2) <= lw] = True
        for i in range(4):
            if i not in arms:  # a closed side: the road's edge runs straight past it
                u = units[i]
                surface &= (cv.x * u[0] + cv.y * u[1]) <= half_w
                v = (-u[1], u[0])
                e = half_w - edge_off
                pa = (e * u[0] - box * v[0], e * u[1] - box * v[1])
                pb = (e * u[0] + box * v[0], e * u[1] + box * v[1])
                white[cv.seg(pa, pb) <= lw] = True
        road |= surface
    elif tile_type in ("dead_end", "parking_lot"):
        end = h - tk.dead_end_margin_m
        mark_axis(arms[0], -end)
        _, _, off = approach(arms[0], -end)
        pa, pb = off(half_w - edge_off)
        qa, qb = off(-half_w + edge_off)
        white[cv.seg(pb, qb) <= lw] = True
    else:  # straight, curve, roadside parking: along every lane
        for lane in content.lanes:
            prims = _lane_prims(lane)
            road |= _dist(cv, prims, 0.0) <= w / 2 + tk.shoulder_m + 1e-9
        for i, d in enumerate(offsets):
            for lane in content.lanes:
                if not lane.name.endswith(f"_{i}") and k > 1:
                    continue
                prims = _lane_prims(lane)
                if i == k - 1:  # the road's edge on its right
                    e_off = -(w / 2 + tk.shoulder_m - edge_off) if lanes > 1 else -(half_w - edge_off)  # fmt: skip
                    near = np.abs(_dist(cv, prims, e_off)) <= lw
                    edge |= near
                    edge_on[near] = _dashes(cv, prims, e_off)[near]
                if i > 0:
                    white |= _dashes(cv, prims, w / 2) & (_dist(cv, prims, w / 2) <= lw)
                first_arm = lane.name.split("_")[1] == tiles.ARMS[tile_type][0]
                if i == 0 and lanes == 2 and first_arm:  # one direction draws the shared line
                    yellow |= _dist(cv, prims, w / 2) <= lw
                    centre_on |= _dashes(cv, prims, w / 2)
                if i == 0 and lanes > 2:  # a double line, always in full
                    solid = _dist(cv, prims, w / 2 - 1.5 * tk.paint_width_m) <= lw
                    yellow |= solid
                    centre_on |= solid
    # stop lines (a dead end's and a lot aisle's end bars too)
    for s in content.stop_lines:
        lane = by_name[s.lane]
        prims = _lane_prims(lane)
        (x0, y0, x1, y1) = prims[0][1][:4]
        ln = math.hypot(x1 - x0, y1 - y0)
        tx, ty = (x1 - x0) / ln, (y1 - y0) / ln
        half_len = tk.lane_width_m / 2
        sw = tk.stop_line_width_m / 2
        pa = (s.centre_m[0] - ty * half_len, s.centre_m[1] + tx * half_len)
        pb = (s.centre_m[0] + ty * half_len, s.centre_m[1] - tx * half_len)
        white |= cv.seg(pa, pb) <= sw
    # parking slots: both sides and the back
    for slot in content.slots:
        yaw = slot.yaw_rad
        c, s_ = math.cos(yaw), math.sin(yaw)
        hw, hd = slot.size_m[0] / 2, slot.size_m[1] / 2
        cx, cy = slot.centre_m

        def pt(fwd: float, left: float) -> Vec2:
            return (cx + fwd * c - left * s_, cy + fwd * s_ + left * c)

        for a, b in (
            (pt(-hd, hw), pt(hd, hw)),
            (pt(-hd, -hw), pt(hd, -hw)),
            (pt(hd, -hw), pt(hd, hw)),
        ):
            white |= cv.seg(a, b) <= lw
        road |= (np.abs((cv.x - cx) * c + (cv.y - cy) * s_) <= hd) & (
            np.abs(-(cv.x - cx) * s_ + (cv.y - cy) * c) <= hw
        )
    if lanes > 2 or not marking.centre_dashed:
        centre_on |= yellow
    if not marking.edge_dashed:
        edge_on[:] = True
    cv.paint(road, asphalt)
    cv.paint(yellow & centre_on & road, marking.centre_rgb or tk.centre_rgb)
    cv.paint(white, tk.line_rgb)
    cv.paint(edge & edge_on, marking.edge_rgb or tk.line_rgb)
    return cv.png()


# --- signs --------------------------------------------------------------------------------------


def _sign_png(kit: Kit, kind: str, spec: SignKindKit, text: str) -> bytes:
    n = kit.sign.texture_px
    img = Image.new("RGB", (n, n), (235, 235, 235))  # the back plate's colour around the shape
    d = ImageDraw.Draw(img)
    c, r = n / 2, n / 2 - 1
    col = tuple(int(v) for v in spec.rgb)
    white, black = (250, 250, 250), (15, 15, 15)

    def poly(k: int, rot: float, rad: float) -> list[tuple[float, float]]:
        return [(c + rad * math.cos(rot + 2 * math.pi * i / k), c - rad * math.sin(rot + 2 * math.pi * i / k)) for i in range(k)]  # fmt: skip

    fg = white
    if spec.shape == "octagon":
        d.polygon(poly(8, math.pi / 8, r), fill=col)
    elif spec.shape == "triangle_down":
        d.polygon(poly(3, -math.pi / 2, r), fill=col)
        d.polygon(poly(3, -math.pi / 2, r * 0.6), fill=white)
    elif spec.shape == "triangle_up":
        d.polygon(poly(3, math.pi / 2, r), fill=col)
        d.polygon(poly(3, math.pi / 2, r * 0.62), fill=white)
        fg = black
    elif spec.shape == "circle":
        d.ellipse((c - r, c - r, c + r, c + r), fill=col)
        if spec.symbol != "bar":
            d.ellipse((c - r * 0.78, c - r * 0.78, c + r * 0.78, c + r * 0.78), fill=white)
            fg = black
    elif spec.shape == "diamond":
        d.polygon(poly(4, 0.0, r), fill=col)
        fg = black
    else:
        d.rectangle((1, 1, n - 2, n - 2), fill=col)
    if spec.symbol == "text" and text:
        px = max(1, int(n * 0.8 / (4 * len(text))))
        wdt = (4 * len(text) - 1) * px
        x0, y0 = c - wdt / 2, c - 2.5 * px
        for k, ch in enumerate(text):
            for row, bits in enumerate(GLYPHS[ch]):
                for col_i, bit in enumerate(bits):
                    if bit == "1":
                        x = x0 + (4 * k + col_i) * px
                        y = y0 + row * px
                        d.rectangle((x, y, x + px - 1, y + px - 1), fill=fg)
    elif spec.symbol == "bar":
        d.rectangle((c - r * 0.6, c - r * 0.15, c + r * 0.6, c + r * 0.15), fill=white)
    elif spec.symbol in ("curve_left", "curve_right"):
        s = -1 if spec.symbol == "curve_left" else 1
        w = max(2, n // 16)
        d.line([(c, c + r * 0.45), (c, c), (c + s * r * 0.3, c - r * 0.3)], fill=fg, width=w)
        tip = (c + s * r * 0.38, c - r * 0.38)
        d.polygon([tip, (tip[0] - s * r * 0.22, tip[1]), (tip[0], tip[1] + r * 0.22)], fill=fg)
    elif spec.symbol == "p":
        px = max(1, n // 10)
        for row, bits in enumerate(GLYPHS["P"]):
            for col_i, bit in enumerate(bits):
                if bit == "1":
                    x, y = c - 1.5 * px + col_i * px, c - 2.5 * px + row * px
                    d.rectangle((x, y, x + px - 1, y + px - 1), fill=white)
    elif spec.symbol == "walker":
        w = max(2, n // 20)
        d.ellipse((c - 2 * w, c - r * 0.3 - 2 * w, c + 2 * w, c - r * 0.3 + 2 * w), fill=fg)
        d.line([(c, c - r * 0.2), (c, c + r * 0.1)], fill=fg, width=w)
        d.line([(c - r * 0.15, c + r * 0.3), (c, c + r * 0.1), (c + r * 0.15, c + r * 0.3)], fill=fg, width=w)  # fmt: skip
    return png_bytes(img)


def tile_textures(
    kit: Kit, tile_keys: set[tuple[str, int]], marking: Marking = KIT_MARKING
) -> dict[str, bytes]:
    """PNG bytes by texture name of the tiles (type, lanes), painted with marking."""
    return {tiles.texture_name(t, n): _tile_png(kit, t, n, marking) for t, n in sorted(tile_keys)}


def generate(
    kit: Kit, tile_keys: set[tuple[str, int]], sign_keys: set[tuple[str, str]]
) -> dict[str, bytes]:
    """PNG bytes by texture name: the tiles (type, lanes) and the signs (kind, texture name)."""
    out = tile_textures(kit, tile_keys)
    for kind, name in sorted(sign_keys):
        spec = kit.sign.kinds[kind]
        text = name.rsplit("_", 1)[1] if kind == "speed_limit" else spec.text
        out[name] = _sign_png(kit, kind, spec, text)
    return out
