"""tools/map import: an OpenDRIVE network as a kit map description (NAME.yaml), its MJCF scene,
JSON sidecar and the textures it uses, in one folder. Every driving lane becomes a road of the
kit with one lane (its centre line as short arcs through points of the file's geometry),
signals become lights with their stop lines, and signs, road marks become markings; the transform (ours = scale * file +
offset_m) and every warning go into the sidecar's `imported_from`. Nothing is written unless the
whole map loads and checks."""

from __future__ import annotations

import math
import shutil
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from autodrive.core.geometry import wrap
from autodrive.maps import mjcf, sidecar, textures
from autodrive.maps.loader import KIT_FILE, MAX_EYE_CAMERAS, load, load_kit
from autodrive.maps.opendrive import arcs, marks, network, xodr
from autodrive.maps.opendrive.lanes import DRIVING_TYPES
from autodrive.maps.opendrive.network import ImportedLane, LaneKey, Transform
from autodrive.maps.model import MapDescriptionError

LIGHT_TYPES = {"1000001", "1000002", "1000009", "1000011"}  # StVO traffic light codes
SIGN_KINDS = {"206": "stop", "205": "give_way", "274": "speed_limit"}  # StVO sign codes
GREEN_S, YELLOW_S, ALL_RED_S = 8.0, 2.0, 2.0  # a generated program's phase per controller group
FLOOR_MARGIN_M = 0.5
# Overhead Eye cameras as Tiny Town's (maps/tiny_town.yaml): 3.3 m up, the roof tag (about
# 0.1 m above the floor) 21 px a side; neighbours overlap by at least a tag and its margin.
EYE_HEIGHT_M, ROOF_M, EYE_OVERLAP_M, EYE_MARGIN_M = 3.3, 0.1, 0.3, 0.1
UNITS_M_S = {"m/s": 1.0, "km/h": 1 / 3.6, "mph": 0.44704, "": 1 / 3.6}  # OpenDRIVE default km/h


def parse_scale(text: str) -> float:
    """'1:14' -> 1/14; '0.25' -> 0.25."""
    try:
        if ":" in text:
            a, b = text.split(":")
            value = float(a) / float(b)
        else:
            value = float(text)
    except (ValueError, ZeroDivisionError):
        raise MapDescriptionError(
            f"--scale: not a scale: {text!r} (give 1:14 or a number)"
        ) from None
    if not (math.isfinite(value) and value > 0):
        raise MapDescriptionError(f"--scale: must be > 0, got {text!r}")
    return value


@dataclass
class Imported:
    description: dict[str, Any]
    warnings: list[str]


def _arc_piece(
    name: str, a: tuple[float, float], m: tuple[float, float], b: tuple[float, float]
) -> dict[str, Any]:
    """The kit's piece from a through m to b: an arc, or a line when they are in a row."""
    c = arcs.through(a, m, b)
    if c is None:
        return {"name": name, "line": {"from_m": list(a), "to_m": list(b)}}
    return {
        "name": name,
        "arc": {
            "centre_m": list(c.centre),
            "radius_m": c.radius,
            "start_deg": math.degrees(c.start_rad),
            "sweep_deg": math.degrees(c.sweep_rad),
        },
    }


def _road(lane: ImportedLane) -> dict[str, Any]:
    pts = lane.points
    pieces = [
        _arc_piece(f"{lane.name}_{k // 2}", pts[k], pts[k + 1], pts[k + 2])
        for k in range(0, len(pts) - 2, 2)
    ]
    return {
        "name": lane.name,
        "width_m": 2 * lane.half_width_m,
        "centre_marking": "none",
        "pieces": pieces,
        "lanes": [{"name": lane.name, "offset_m": 0.0, "direction": "forward"}],
    }


def _along(lane: ImportedLane, s_m: float) -> tuple[float, tuple[float, float], float]:
    """Distance along the lane's centre line [m, ours] to the point at the file's s, the point
    and the heading there."""
    best = min(range(len(lane.s_m)), key=lambda k: abs(lane.s_m[k] - s_m))
    along = sum(math.dist(a, b) for a, b in zip(lane.points[:best], lane.points[1 : best + 1]))
    k0, k1 = (best, best + 1) if best + 1 < len(lane.points) else (best - 1, best)
    (x0, y0), (x1, y1) = lane.points[k0], lane.points[k1]
    return along, lane.points[best], math.atan2(y1 - y0, x1 - x0)


class _Signals:
    """Lights (with their stop lines) and signs from the roads' signals."""

    def __init__(
        self,
        net: xodr.Network,
        lanes: dict[LaneKey, ImportedLane],
        tf: Transform,
        clearance_m: float,
        warnings: list[str],
    ) -> None:
        self.net, self.lanes, self.tf, self.clearance_m = net, lanes, tf, clearance_m
        self.warnings = warnings
        self.stop_lines: list[dict[str, Any]] = []
        self.lights: list[dict[str, Any]] = []
        self.signs: list[dict[str, Any]] = []
        self.unsupported: list[str] = []
        self.lights_of: dict[str, list[int]] = {}  # signal id -> our light ids
        group_of = {sid: c.id for c in net.controllers for sid in c.signal_ids}
        self.groups: list[str] = []
        for r in net.roads.values():
            for sig in r.signals:
                self.add(r, sig, group_of.get(sig.id, f"signal_{sig.id}"))

    def approach(self, r: xodr.Road, sig: xodr.Signal) -> list[ImportedLane]:
        """The driving lanes the signal applies to, rightmost first (by lateral position)."""
        sec = (
            max(i for i, s in enumerate(r.sections) if s.s_m <= sig.s_m + 1e-9)
            if r.sections[0].s_m <= sig.s_m
            else 0
        )
        out = []
        for (rid, i, lid), lane in self.lanes.items():
            if rid != r.id or i != sec:
                continue
            fwd = (lid < 0) == (r.rule == "RHT")
            if sig.orientation == "+" and not fwd or sig.orientation == "-" and fwd:
                continue
            if sig.valid_lanes is not None and not min(sig.valid_lanes) <= lid <= max(
                sig.valid_lanes
            ):
                continue
            out.append(lane)
        return sorted(out, key=lambda ln: abs(ln.key[2]), reverse=True)

    def add(self, r: xodr.Road, sig: xodr.Signal, group: str) -> None:
        what = f"signal '{sig.id}' on road '{r.id}' (type {sig.type}, subtype {sig.subtype}, country {sig.country or '-'})"
        is_light = sig.type in LIGHT_TYPES
        kind = SIGN_KINDS.get(sig.type)
        if not is_light and kind is None:
            self.unsupported.append(what)
            return
        lanes = self.approach(r, sig)
        if not lanes:
            self.warnings.append(f"{what}: applies to no driving lane; not placed")
            return
        if kind is not None:
            along, _, _ = _along(lanes[0], sig.s_m)
            spec: dict[str, Any] = {
                "id": len(self.signs) + 1,
                "kind": kind,
                "lane": lanes[0].name,
                "along_m": along,
            }
            if kind == "speed_limit":
                if sig.value is None or sig.unit not in UNITS_M_S:
                    self.unsupported.append(
                        f"{what}: speed limit without a value in m/s, km/h or mph"
                    )
                    return
                spec["speed_limit_m_s"] = round(sig.value * UNITS_M_S[sig.unit] * self.tf.scale, 6)
            self.signs.append(spec)
            return
        if group not in self.groups:
            self.groups.append(group)
        _, (x, y), h = _along(lanes[0], sig.s_m)
        d = lanes[0].half_width_m + self.clearance_m
        pole = [x + d * math.sin(h), y - d * math.cos(h)]  # right of the rightmost lane
        for lane in lanes:
            _, (sx, sy), _ = _along(lane, sig.s_m)
            junction, entry = self.junction_ahead(lane)
            stop = f"stop_{network.safe_name(sig.id)}_{lane.name}"
            self.stop_lines.append(
                {
                    "name": stop,
                    "lane": lane.name,
                    "centre_m": [sx, sy],
                    "length_m": 2 * lane.half_width_m,
                }
            )
            self.lights_of.setdefault(sig.id, []).append(len(self.lights) + 1)
            self.lights.append(
                {
                    "id": len(self.lights) + 1,
                    "stop_line": stop,
                    "group": group,
                    "position_m": pole,
                    "yaw_deg": math.degrees(h + math.pi),
                    "junction": junction,
                    "heading_rad": entry,
                }
            )

    def junction_ahead(self, lane: ImportedLane) -> tuple[str | None, float]:
        """The junction the lane leads into (through its road's later lane sections) and the
        heading [rad] where it enters it; (None, 0) if it leads into none."""
        here = lane
        for _ in range(len(self.lanes)):
            (ex, ey), (fx, fy) = here.points[-2], here.points[-1]
            for key in here.successors:
                j = self.net.roads[key[0]].junction
                if j != "-1":
                    return j, math.atan2(fy - ey, fx - ex)
            same_road = [k for k in here.successors if k[0] == here.key[0]]
            if not same_road:
                break
            here = self.lanes[same_road[0]]
        return None, 0.0

    def crossings(self) -> None:
        """Each light's crosses: the lights before the same junction whose approaches (their
        lanes' headings where they enter it) are neither the same way nor opposite (more than
        0.1 rad from either), as the kit's intersection tiles pair theirs. A controller that would show two crossing approaches
        green at once is split (the later signal gets its own phase), with a warning."""
        for light in self.lights:
            light["crosses"] = []
        for i, a in enumerate(self.lights):
            for b in self.lights[i + 1 :]:
                if a["junction"] is None or a["junction"] != b["junction"]:
                    continue
                dyaw = abs(wrap(a["heading_rad"] - b["heading_rad"]))
                if not 0.1 < dyaw < math.pi - 0.1:
                    continue
                a["crosses"].append(b["id"])
                b["crosses"].append(a["id"])
                if a["group"] == b["group"]:
                    self.warnings.append(
                        f"controller '{a['group']}': lights {a['id']} and {b['id']} cross at "
                        f"junction '{a['junction']}'; light {b['id']} given its own phase"
                    )
                    b["group"] = f"{b['group']}/light_{b['id']}"
                    self.groups.append(b["group"])

    def programs(self) -> list[dict[str, Any]]:
        """The lights with fixed-time programs: one phase per controller (signals without one:
        a phase each), in turn, with an all-red interval between phases."""
        self.crossings()
        n = len(self.groups)
        phase = GREEN_S + YELLOW_S + ALL_RED_S
        out = []
        for light in self.lights:
            del light["junction"], light["heading_rad"]
            if not light["crosses"]:
                del light["crosses"]
            k = self.groups.index(light.pop("group"))
            light["program"] = {
                "cycle_s": phase * max(2, n),
                "offset_s": phase * k,
                "green_s": GREEN_S,
                "yellow_s": YELLOW_S,
            }
            out.append(light)
        return out


def _axis_centres(lo: float, hi: float, view: float) -> list[float]:
    """Camera centres along one axis so that views of width view [m] cover lo..hi, neighbours
    overlapping by EYE_OVERLAP_M at least."""
    span = hi - lo
    if span <= view:
        return [round((lo + hi) / 2, 3) + 0.0]
    n = math.ceil((span - EYE_OVERLAP_M) / (view - EYE_OVERLAP_M))
    step = (span - view) / (n - 1)
    return [round(lo + view / 2 + k * step, 3) + 0.0 for k in range(n)]


def eye_cameras(lanes: list[ImportedLane], kit: Any, warnings: list[str]) -> list[dict[str, Any]]:
    """A grid of overhead cameras over the driving lanes' extent (their centre lines and half
    widths, plus EYE_MARGIN_M), each seeing its part of the roof plane (ROOF_M up) whole: at
    EYE_HEIGHT_M, or as much higher as the simulator's MAX_EYE_CAMERAS need (with a warning:
    the roof tags are smaller in the images then)."""
    e = kit.eye_camera
    pad = max(ln.half_width_m for ln in lanes) + EYE_MARGIN_M
    xs = [p[0] for ln in lanes for p in ln.points]
    ys = [p[1] for ln in lanes for p in ln.points]
    height = EYE_HEIGHT_M
    while True:
        half_y = (height - ROOF_M) * math.tan(math.radians(e.fovy_deg / 2))
        view_x, view_y = 2 * half_y * e.width_px / e.height_px, 2 * half_y
        cx = _axis_centres(min(xs) - pad, max(xs) + pad, view_x)
        cy = _axis_centres(min(ys) - pad, max(ys) + pad, view_y)
        if len(cx) * len(cy) <= MAX_EYE_CAMERAS:
            break
        height = round(height + 0.1, 1)
    if height > EYE_HEIGHT_M:
        tag_px = (
            0.08 * 0.5 * e.height_px / math.tan(math.radians(e.fovy_deg / 2)) / (height - ROOF_M)
        )
        warnings.append(
            f"eye_cameras: {len(cx) * len(cy)} cameras {height:g} m up to cover the network "
            f"(roof tags {tag_px:.0f} px a side, {EYE_HEIGHT_M:g} m: 21 px)"
        )
    grid = [(x, y) for y in cy for x in cx]
    return [
        {"name": f"eye{k + 1}", "centre_m": [x, y], "height_m": height}
        for k, (x, y) in enumerate(grid)
    ]


def describe(path: Path, scale: float, max_junctions: int = 1) -> Imported:
    """The kit description of an OpenDRIVE file (plain YAML types)."""
    net = xodr.read(path)
    warnings: list[str] = []
    for r in net.roads.values():
        if r.sloped:
            warnings.append(f"road '{r.id}': elevation flattened (the kit's maps are flat)")
        others = sorted(
            {ln.type for s in r.sections for ln in s.lanes if ln.type not in DRIVING_TYPES}
        )
        if others:
            warnings.append(
                f"road '{r.id}': lanes of type {', '.join(others)} not drawn (not driven)"
            )
    lanes, tf = network.build(net, scale, warnings)
    kit = load_kit(KIT_FILE)
    sig = _Signals(net, lanes, tf, kit.tiles.roadside_clearance_m, warnings)
    routes = network.routes(net, lanes, max_junctions)
    reach = max(max(abs(c) for p in ln.points for c in p) for ln in lanes.values())
    first = (
        lanes[next(iter(lanes))]
        if not routes
        else next(l for l in lanes.values() if l.name == routes[0][1][0])
    )
    (x0, y0), (x1, y1) = first.points[0], first.points[1]
    desc: dict[str, Any] = {
        "floor_half_size_m": math.ceil((reach + FLOOR_MARGIN_M) * 10) / 10,
        "floor_surface": "lawn",
        "spawn": {"position_m": [x0, y0], "yaw_deg": math.degrees(math.atan2(y1 - y0, x1 - x0))},
        "imported_from": {
            "file": path.name,
            "scale": scale,
            "offset_m": list(tf.offset_m),
            "opendrive_version": net.version,
            "warnings": warnings,
            "unsupported_signals": sig.unsupported,
        },
        "roads": [_road(ln) for ln in lanes.values()],
        "markings": marks.markings(net, lanes, tf, warnings),
        "stop_lines": sig.stop_lines,
        "traffic_lights": sig.programs(),
        "signs": sig.signs,
        "routes": [{"name": n, "lanes": ls} for n, ls in routes],
        "terrain_patches": [],
        "walls": [],
        "boxes": [],
        "cones": [],
        "parking_slots": [],
        "eye_cameras": eye_cameras(list(lanes.values()), kit, warnings),
    }
    if sig.lights_of:  # the schema takes no empty mapping
        desc["imported_from"]["signal_lights"] = sig.lights_of
    return Imported(desc, warnings + [f"unsupported {u}" for u in sig.unsupported])


HEADER = (
    "# Imported from {file} by tools/map import (scale {scale:g}, ours = scale * file + "
    "offset_m). Generated: edit the OpenDRIVE file and import again.\n"
)


def write(path: Path, scale: float, name: str, out_dir: Path, max_junctions: int = 1) -> Imported:
    """Writes out_dir/NAME.yaml, .xml, .json and textures/*.png; raises MapDescriptionError
    (OpenDriveError for the file itself) and then writes nothing."""
    if not network.safe_name(name) == name:
        raise MapDescriptionError(f"--name: {name!r}: use letters, digits and underscores")
    imported = describe(path, scale, max_junctions)
    with tempfile.TemporaryDirectory() as tmp:
        stage = Path(tmp)
        yml = stage / f"{name}.yaml"
        yml.write_text(
            HEADER.format(file=path.name, scale=scale)
            + yaml.safe_dump(imported.description, sort_keys=False, width=100)
        )
        m = load(yml, KIT_FILE)
        (stage / f"{name}.xml").write_text(mjcf.generate(m))
        (stage / f"{name}.json").write_text(sidecar.generate(m))
        sign_keys = {
            (s.kind, textures.sign_texture_name(s.kind, s.speed_limit_m_s))
            for s in m.placed_signs()
        }
        tex = stage / textures.DIR_NAME
        tex.mkdir()
        for n, png in textures.generate(m.kit, set(), sign_keys).items():
            (tex / f"{n}.png").write_bytes(png)
        out_dir.mkdir(parents=True, exist_ok=True)
        for f in sorted(stage.rglob("*")):
            if f.is_file():
                dest = out_dir / f.relative_to(stage)
                dest.parent.mkdir(parents=True, exist_ok=True)
                shutil.copyfile(f, dest)
    return imported
