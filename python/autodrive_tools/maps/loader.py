"""Reads a map description and the kit from YAML and checks them: structure (schema.py) first,
then the facts that need the whole map (names unique, things on the floor, slots apart, roads
connected, stop lines on their lanes). Every error names the file and the dotted key."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from typing import Any, Union

import yaml

from . import geometry
from .description import MapDescription
from .model import Kit, MapDescriptionError, MapFile, Vec2, rect_corners
from .schema import build, fail
from ..paths import REPO_ROOT

MAPS_DIR: Path = REPO_ROOT / "sim" / "mujoco_hil" / "maps"
KIT_FILE: Path = MAPS_DIR / "kit.yaml"
JOIN_TOLERANCE_M = 1e-6  # road pieces must meet end to start within this
ON_LANE_TOLERANCE_M = 0.01  # a stop line's centre must be this close to its lane's centre line


def names(maps_dir: Path = MAPS_DIR) -> list[str]:
    """The maps in a folder (default: the shipped ones): every <name>.yaml but kit.yaml."""
    return sorted(p.stem for p in Path(maps_dir).glob("*.yaml") if p.name != KIT_FILE.name)


def _read_yaml(source: Path) -> Any:
    try:
        with source.open() as f:  # a stream with a name: YAML errors then name the file
            return yaml.safe_load(f)
    except OSError as err:
        raise MapDescriptionError(f"{source}: cannot read ({err.strerror})") from err
    except yaml.YAMLError as err:
        raise MapDescriptionError(f"{source}: not valid YAML ({err})") from err


def load_kit(path: Union[Path, str, None] = None) -> Kit:
    source = Path(path) if path is not None else KIT_FILE
    kit = build(Kit, _read_yaml(source), source)
    kit = dataclasses.replace(kit, source=source)
    _check_positive(kit, source, "")
    if kit.road.arc_segments_per_90deg < 1:
        raise fail(source, "road.arc_segments_per_90deg", "must be at least 1")
    return kit


def _check_positive(obj: Any, source: Path, key: str) -> None:
    """Every number in the kit is a size, friction or count: all must be > 0 (rgba >= 0)."""
    for f in dataclasses.fields(obj):
        v = getattr(obj, f.name)
        sub = f"{key}.{f.name}" if key else f.name
        if f.name == "source":
            continue
        if dataclasses.is_dataclass(v):
            _check_positive(v, source, sub)
        elif isinstance(v, dict):
            for k, item in v.items():
                _check_positive(item, source, f"{sub}.{k}")
        elif f.name.endswith("rgba"):
            if not all(0 <= c <= 1 for c in v):
                raise fail(source, sub, f"colour values must be in 0..1, got {list(v)}")
        elif isinstance(v, (int, float)) and not v > 0:
            raise fail(source, sub, f"must be > 0, got {v}")


def load(name_or_path: Union[str, Path], kit_path: Union[Path, str, None] = None) -> MapDescription:
    """A map by name ('parking_school') or by YAML path, built with the kit (maps/kit.yaml
    unless given); raises MapDescriptionError naming the file and the dotted key."""
    text = str(name_or_path)
    source = Path(text) if ("/" in text or text.endswith(".yaml")) else MAPS_DIR / f"{text}.yaml"
    if not source.is_file():
        raise MapDescriptionError(
            f"{source}: no such map description (shipped maps: {', '.join(names())})"
        )
    kit = load_kit(kit_path)
    data = _read_yaml(source)
    desc = build(MapFile, data, source)
    m = MapDescription(
        **{f.name: getattr(desc, f.name) for f in dataclasses.fields(MapFile)},
        name=source.stem,
        source=source,
        kit=kit,
    )
    _Checker(m, kit).run()
    return m


class _Checker:
    def __init__(self, m: MapDescription, kit: Kit) -> None:
        self.m, self.kit, self.src = m, kit, m.source
        self.seen: dict[str, str] = {}

    def err(self, key: str, what: str) -> MapDescriptionError:
        return fail(self.src, key, what)

    def unique(self, name: str, key: str) -> None:
        if name in self.seen:
            raise self.err(key, f"name '{name}' is already used by {self.seen[name]}")
        self.seen[name] = key

    def positive(self, values: tuple[float, ...] | float, key: str) -> None:
        vs = values if isinstance(values, tuple) else (values,)
        if not all(v > 0 for v in vs):
            raise self.err(key, f"must be > 0, got {list(vs) if len(vs) > 1 else vs[0]}")

    def on_floor(self, points: list[Vec2], key: str) -> None:
        h = self.m.floor_half_size_m
        for x, y in points:
            if abs(x) > h + 1e-9 or abs(y) > h + 1e-9:
                raise self.err(key, f"({x:g}, {y:g}) is off the floor (|x|, |y| <= {h:g} m)")

    def surface(self, name: str, key: str) -> None:
        if name not in self.kit.surfaces:
            raise self.err(key, f"unknown surface '{name}' (the kit has {list(self.kit.surfaces)})")

    def run(self) -> None:
        m = self.m
        self.positive(m.floor_half_size_m, "floor_half_size_m")
        self.surface(m.floor_surface, "floor_surface")
        self.on_floor([m.spawn.position_m], "spawn.position_m")
        self.patches()
        for i, w in enumerate(m.walls):
            key = f"walls[{i}]"
            self.unique(w.name, f"{key}.name")
            if w.normal not in ((1, 0), (-1, 0), (0, 1), (0, -1)):
                raise self.err(
                    f"{key}.normal",
                    f"must be [1, 0], [-1, 0], [0, 1] or [0, -1], got {list(w.normal)}",
                )
            self.positive(w.length_m, f"{key}.length_m")
        for i, b in enumerate(m.boxes):
            key = f"boxes[{i}]"
            self.unique(b.name, f"{key}.name")
            self.positive(b.size_m, f"{key}.size_m")
            self.on_floor(rect_corners(b.centre_m, b.size_m[:2], b.yaw_rad), f"{key}.centre_m")
        for i, c in enumerate(m.cones):
            self.unique(c.name, f"cones[{i}].name")
            self.on_floor([c.position_m], f"cones[{i}].position_m")
        self.slots()
        self.roads()
        self.stop_lines()
        for kind in ("traffic_lights", "signs"):
            for i, fx in enumerate(getattr(m, kind)):
                self.unique(fx.id, f"{kind}[{i}].id")
                self.on_floor([fx.position_m], f"{kind}[{i}].position_m")

    def patches(self) -> None:
        done: list[tuple[str, list[Vec2]]] = []
        for i, p in enumerate(self.m.terrain_patches):
            key = f"terrain_patches[{i}]"
            self.unique(p.name, f"{key}.name")
            self.surface(p.surface, f"{key}.surface")
            self.positive(p.size_m, f"{key}.size_m")
            corners = rect_corners(p.centre_m, p.size_m, 0.0)
            self.on_floor(corners, f"{key}.centre_m")
            for other, oc in done:  # one friction under a wheel: patches must not overlap
                if geometry.convex_overlap(corners, oc):
                    raise self.err(key, f"patch '{p.name}' overlaps patch '{other}'")
            done.append((p.name, corners))

    def slots(self) -> None:
        done: list[tuple[str, list[Vec2]]] = []
        boxes = [(b.name, rect_corners(b.centre_m, b.size_m[:2], b.yaw_rad)) for b in self.m.boxes]
        for i, s in enumerate(self.m.parking_slots):
            key = f"parking_slots[{i}]"
            self.unique(s.name, f"{key}.name")
            self.positive(s.size_m, f"{key}.size_m")
            corners = s.corners_m()
            self.on_floor(corners, f"{key}.centre_m")
            for other, oc in done + boxes:
                if geometry.convex_overlap(corners, oc):
                    raise self.err(key, f"slot '{s.name}' overlaps '{other}'")
            done.append((s.name, corners))

    def roads(self) -> None:
        lanes: set[str] = set()
        roads: set[str] = set()
        for i, r in enumerate(self.m.roads):
            key = f"roads[{i}]"
            if r.name in roads:
                raise self.err(f"{key}.name", f"road '{r.name}' is given twice")
            roads.add(r.name)
            self.positive(r.width_m, f"{key}.width_m")
            if not r.pieces:
                raise self.err(f"{key}.pieces", "a road needs at least one piece")
            prev_end: Vec2 | None = None
            for j, p in enumerate(r.pieces):
                pk = f"{key}.pieces[{j}]"
                self.unique(f"road_{p.name}", f"{pk}.name")  # its drawn geom's name
                if (p.line is None) == (p.arc is None):
                    raise self.err(pk, "give exactly one of 'line' and 'arc'")
                if p.line is not None and math.dist(p.line.from_m, p.line.to_m) == 0:
                    raise self.err(f"{pk}.line", "from_m and to_m are the same point")
                if p.arc is not None:
                    self.positive(p.arc.radius_m, f"{pk}.arc.radius_m")
                    if p.arc.sweep_deg == 0 or abs(p.arc.sweep_deg) > 360:
                        raise self.err(f"{pk}.arc.sweep_deg", "must be non-zero, at most 360")
                start, end = geometry.piece_ends(p)
                if prev_end is not None and math.dist(prev_end, start) > JOIN_TOLERANCE_M:
                    raise self.err(
                        pk,
                        f"starts at ({start[0]:g}, {start[1]:g}), not where the previous piece "
                        f"ends ({prev_end[0]:g}, {prev_end[1]:g})",
                    )
                prev_end = end
                n = 16
                pts = [
                    geometry.piece_point(p, k / n, s * r.width_m / 2)[0]
                    for k in range(n + 1)
                    for s in (-1, 1)
                ]
                self.on_floor(pts, pk)
            for j, lane in enumerate(r.lanes):
                lk = f"{key}.lanes[{j}]"
                if lane.name in lanes:
                    raise self.err(f"{lk}.name", f"lane '{lane.name}' is given twice")
                lanes.add(lane.name)
                if not abs(lane.offset_m) < r.width_m / 2:
                    raise self.err(
                        f"{lk}.offset_m",
                        f"{lane.offset_m:g} m is off the road (width {r.width_m:g} m)",
                    )

    def stop_lines(self) -> None:
        lanes = {lane.name: lane for lane in self.m.lanes()}
        for i, s in enumerate(self.m.stop_lines):
            key = f"stop_lines[{i}]"
            self.unique(s.name, f"{key}.name")
            self.positive(s.length_m, f"{key}.length_m")
            if s.lane not in lanes:
                raise self.err(f"{key}.lane", f"no lane '{s.lane}' (lanes: {sorted(lanes)})")
            d, _ = geometry.nearest_on_polyline(
                s.centre_m, geometry.centre_line(lanes[s.lane], 0.01)
            )
            if d > ON_LANE_TOLERANCE_M:
                raise self.err(f"{key}.centre_m", f"{d:.3f} m off lane '{s.lane}' centre line")
