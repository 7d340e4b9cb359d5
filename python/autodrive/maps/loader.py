"""Reads a map description and the kit from YAML and checks them: structure (schema.py) first,
then the facts that need the whole map (names unique, things on the floor, slots apart, roads
connected, stop lines on their lanes). Every error names the file and the dotted key."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from typing import Any, Union

import yaml

from autodrive.maps import geometry, tiles
from autodrive.maps.description import MapDescription
from autodrive.maps.model import Kit, MapDescriptionError, MapFile, Vec2, rect_corners
from autodrive.maps.schema import build, fail
from autodrive.core.settings import settings
from autodrive.core.geometry import wrap

MAPS_DIR: Path = settings().maps_dir
KIT_FILE: Path = MAPS_DIR / "kit.yaml"
JOIN_TOLERANCE_M = 1e-6  # road pieces must meet end to start within this
TILE_JOIN_TOLERANCE_M = 0.001  # lanes of neighbouring tiles, and a route's lanes, meet within this
TILE_JOIN_TOLERANCE_RAD = 0.001  # ... with the same heading (a smooth, tangent-continuous path)
ON_LANE_TOLERANCE_M = 0.01  # a stop line's centre must be this close to its lane's centre line

MAX_LATE_OBSTACLES = 8  # the simulator's SCN_MAX_MAP_LATE_BOXES (scenario.h)
MAX_EYE_CAMERAS = 8  # the simulator's CAMERAS_MAX_EYES (app/include/cameras.h)
TAG36H11_CODES = 587  # ids 0..586
MIN_REFERENCE_TAG_ID = (
    100  # below: the cars' roof tags (mjcf_gen.c mjcf_gen_tag_id: car i has id i)
)


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
    """Every number in the kit is a size, friction, time or count: all must be > 0, colours
    (rgba in 0..1, rgb in 0..255) may be 0."""
    if dataclasses.is_dataclass(obj):
        for f in dataclasses.fields(obj):
            if f.name != "source":
                _check_positive(getattr(obj, f.name), source, f"{key}.{f.name}" if key else f.name)
    elif isinstance(obj, dict):
        for k, item in obj.items():
            _check_positive(item, source, f"{key}.{k}")
    elif key.endswith("rgba") or ".lamp_off_rgba." in key:
        if not all(0 <= c <= 1 for c in obj):
            raise fail(source, key, f"colour values must be in 0..1, got {list(obj)}")
    elif key.endswith("rgb"):
        if not all(0 <= c <= 255 for c in obj):
            raise fail(source, key, f"colour values must be in 0..255, got {list(obj)}")
    elif isinstance(obj, tuple):
        for i, v in enumerate(obj):
            _check_positive(v, source, f"{key}[{i}]")
    elif isinstance(obj, (int, float)) and not isinstance(obj, bool) and not obj > 0:
        raise fail(source, key, f"must be > 0, got {obj}")


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
        if not 0 <= m.options.light_level <= 1:
            raise self.err("options.light_level", f"must be in 0..1, got {m.options.light_level}")
        self.tiles()
        self.slots()
        self.roads()
        self.markings()
        self.stop_lines()
        self.routes()
        self.lights()
        self.signs()
        for i, p in enumerate(m.parked):
            self.unique(f"parked_{p.slot}", f"parked[{i}].slot")
            if p.slot not in {s.name for s in m.slots()}:
                raise self.err(f"parked[{i}].slot", f"no parking slot '{p.slot}'")
        self.eye_cameras()
        self.reference_tags()
        if len(m.late_obstacles) > MAX_LATE_OBSTACLES:
            raise self.err(
                "late_obstacles",
                f"at most {MAX_LATE_OBSTACLES} (the simulator's SCN_MAX_MAP_LATE_BOXES), "
                f"got {len(m.late_obstacles)}",
            )
        for i, o in enumerate(m.late_obstacles):
            key = f"late_obstacles[{i}]"
            self.unique(o.name, f"{key}.name")
            self.positive(o.size_m, f"{key}.size_m")
            self.on_floor(rect_corners(o.centre_m, o.size_m[:2], o.yaw_rad), f"{key}.centre_m")
            if (o.appear_s is None) == (o.trigger_radius_m is None):
                raise self.err(key, "give exactly one of appear_s and trigger_radius_m")
            for v, k in ((o.appear_s, "appear_s"), (o.trigger_radius_m, "trigger_radius_m")):
                if v is not None and not v > 0:
                    raise self.err(f"{key}.{k}", f"must be > 0, got {v}")

    def tiles(self) -> None:
        kit = self.kit.tiles
        done: list[tuple[str, list[Vec2]]] = []
        contents = []
        for i, t in enumerate(self.m.tiles):
            key = f"tiles[{i}]"
            self.unique(t.name, f"{key}.name")
            if t.lanes not in tiles.LANE_COUNTS or str(t.lanes) not in kit.cell_m:
                raise self.err(f"{key}.lanes", f"must be one of {list(tiles.LANE_COUNTS)}, got "
                               f"{t.lanes}")  # fmt: skip
            if abs(t.rotation_deg / 90 - round(t.rotation_deg / 90)) > 1e-9:
                raise self.err(f"{key}.rotation_deg", f"must be a multiple of 90, got "
                               f"{t.rotation_deg:g}")  # fmt: skip
            size = tiles.tile_size_m(kit, t)
            corners = rect_corners(t.centre_m, (size, size), 0.0)
            self.on_floor(corners, f"{key}.centre_m")
            for other, oc in done:
                if geometry.convex_overlap(corners, oc):
                    raise self.err(key, f"tile '{t.name}' overlaps tile '{other}'")
            done.append((t.name, corners))
            contents.append(self.m.tile_contents()[i])
        starts = [(c.spec.name, p) for c in contents for p in c.ports if p[1] == "start"]
        ends = [(c.spec.name, p) for c in contents for p in c.ports if p[1] == "end"]
        for i, c in enumerate(contents):
            for tl in c.lanes:
                self.unique(tl.name, f"tiles[{i}] lane")
            for s in c.stop_lines:
                self.unique(s.name, f"tiles[{i}] stop line")
            for lane, end, p, yaw in c.ports:
                others = ends if end == "start" else starts
                if not any(
                    name != c.spec.name
                    and math.dist(p, q[2]) <= TILE_JOIN_TOLERANCE_M
                    and abs(wrap(yaw - q[3])) <= TILE_JOIN_TOLERANCE_RAD
                    for name, q in others
                ):
                    what = "enters" if end == "start" else "leaves"
                    other = "ends" if end == "start" else "starts"
                    raise self.err(
                        f"tiles[{i}]",
                        f"tile '{c.spec.name}' does not connect: its lane '{lane}' {what} it at "
                        f"({p[0]:g}, {p[1]:g}) heading {math.degrees(yaw):.0f} deg, where no "
                        f"other tile's lane {other} (put a matching tile there, or a dead_end)",
                    )

    def routes(self) -> None:
        lanes = {lane.name for lane in self.m.lanes()}
        names: set[str] = set()
        for i, r in enumerate(self.m.routes):
            key = f"routes[{i}]"
            if r.name in names:
                raise self.err(f"{key}.name", f"route '{r.name}' is given twice")
            names.add(r.name)
            if not r.lanes:
                raise self.err(f"{key}.lanes", "a route needs at least one lane")
            for j, name in enumerate(r.lanes):
                if name not in lanes:
                    raise self.err(f"{key}.lanes[{j}]", f"no lane '{name}'")
            pairs = list(zip(r.lanes, r.lanes[1:])) + (
                [(r.lanes[-1], r.lanes[0])] if r.loop else []
            )
            for j, (a, b) in enumerate(pairs):
                pa, pb = self.m.centre_line(a)[-1], self.m.centre_line(b)[0]
                gap = math.dist(pa[:2], pb[:2])
                turn = abs(wrap(pa[2] - pb[2]))
                if gap > TILE_JOIN_TOLERANCE_M or turn > TILE_JOIN_TOLERANCE_RAD:
                    raise self.err(
                        f"{key}.lanes[{(j + 1) % len(r.lanes)}]",
                        f"lane '{b}' does not start where lane '{a}' ends (gap {gap * 1000:.1f} "
                        f"mm, heading change {math.degrees(turn):.1f} deg)",
                    )
        for i, s in enumerate(self.m.spawns):
            key = f"spawns[{i}]"
            self.unique(f"spawn_{s.name}", f"{key}.name")
            if s.route is not None:
                if s.route not in names:
                    raise self.err(f"{key}.route", f"no route '{s.route}'")
                if s.position_m is not None or s.yaw_deg is not None:
                    raise self.err(key, "give a route (and along_m) or position_m and yaw_deg")
                if (s.along_m or 0.0) < 0 or (s.along_m or 0.0) > self.m.route(s.route).length_m:
                    raise self.err(f"{key}.along_m", f"must be within the route's length")
            elif s.position_m is None or s.yaw_deg is None:
                raise self.err(key, "give a route (and along_m) or position_m and yaw_deg")
        for i, sp in enumerate(self.m.named_spawns()):
            self.on_floor([(sp.pose.x_m, sp.pose.y_m)], f"spawns[{i}]")

    def eye_cameras(self) -> None:
        cams = self.m.eye_cameras
        if len(cams) > MAX_EYE_CAMERAS:
            raise self.err("eye_cameras", f"at most {MAX_EYE_CAMERAS}, got {len(cams)}")
        for i, c in enumerate(cams):
            key = f"eye_cameras[{i}]"
            # the name in capitals is a channel's <CAM>: letters and digits, no underscore
            if not (c.name.isalnum() and c.name.islower() and c.name.startswith("eye")):
                raise self.err(
                    f"{key}.name", f"'{c.name}': must be eye<letters or digits>, lower case"
                )
            self.unique(c.name, f"{key}.name")
            self.on_floor([c.centre_m], f"{key}.centre_m")
            self.positive(c.height_m, f"{key}.height_m")

    def reference_tags(self) -> None:
        for i, t in enumerate(self.m.reference_tags):
            key = f"reference_tags[{i}]"
            if not MIN_REFERENCE_TAG_ID <= t.id < TAG36H11_CODES:
                raise self.err(
                    f"{key}.id",
                    f"must be in {MIN_REFERENCE_TAG_ID}..{TAG36H11_CODES - 1} (tag36h11; lower "
                    f"ids are the cars' roof tags), got {t.id}",
                )
            self.unique(f"reftag{t.id}", f"{key}.id")
            self.on_floor([t.centre_m], f"{key}.centre_m")
            self.positive(t.size_m, f"{key}.size_m")

    def lights(self) -> None:
        stops = {s.name for s in self.m.all_stop_lines()}
        kit = self.kit.traffic_light
        for i, spec in enumerate(self.m.traffic_lights):
            key = f"traffic_lights[{i}]"
            if spec.id < 1:
                raise self.err(f"{key}.id", f"must be 1 or more, got {spec.id}")
            self.unique(f"tl{spec.id}", f"{key}.id")
            if spec.stop_line not in stops:
                raise self.err(f"{key}.stop_line", f"no stop line '{spec.stop_line}' (has "
                               f"{sorted(stops)})")  # fmt: skip
            if (spec.position_m is None) != (spec.yaw_deg is None):
                raise self.err(key, "give both position_m and yaw_deg, or neither")
            ids = {t.id for t in self.m.traffic_lights}
            for j, other in enumerate(spec.crosses):
                if other == spec.id or other not in ids:
                    raise self.err(f"{key}.crosses[{j}]", f"must name another light of the map "
                                   f"(has {sorted(ids - {spec.id})}), got {other}")  # fmt: skip
            p = spec.program
            self.positive((p.cycle_s, p.green_s, p.yellow_s), f"{key}.program")
            if p.green_s + p.yellow_s >= p.cycle_s:
                raise self.err(
                    f"{key}.program",
                    f"green_s + yellow_s must be < cycle_s (red for "
                    f"the rest), got {p.green_s:g} + {p.yellow_s:g} >= {p.cycle_s:g}",
                )
        placed = self.m.lights()
        for i, light in enumerate(placed):
            self.on_floor([light.position_m], f"traffic_lights[{i}].position_m")
        by_id = {light.id: (i, light) for i, light in enumerate(placed)}
        for a, b in self.m.light_conflicts():
            (ia, la), (ib, lb) = by_id[a], by_id[b]
            pa, pb = la.program, lb.program
            key = f"traffic_lights[{ib}].program"
            if abs(pa.cycle_s - pb.cycle_s) > 1e-9:
                raise self.err(key, f"light {b} crosses light {a}: their cycles must be equal "
                               f"({pb.cycle_s:g} s != {pa.cycle_s:g} s)")  # fmt: skip
            t = pa.cycle_s
            la_s, lb_s = pa.green_s + pa.yellow_s, pb.green_s + pb.yellow_s
            gap1 = (pb.offset_s - pa.offset_s - la_s) % t  # all red after a's yellow
            gap2 = t - la_s - lb_s - gap1  # all red after b's yellow
            if min(gap1, gap2) < kit.min_all_red_s - 1e-9:
                raise self.err(key, f"light {b} crosses light {a} but the all-red interval "
                               f"between them is {max(0.0, min(gap1, gap2)):g} s (at least "
                               f"{kit.min_all_red_s:g} s)")  # fmt: skip

    def signs(self) -> None:
        kinds = self.kit.sign.kinds
        lanes = {lane.name for lane in self.m.lanes()}
        for i, s in enumerate(self.m.signs):
            key = f"signs[{i}]"
            if s.id < 1:
                raise self.err(f"{key}.id", f"must be 1 or more, got {s.id}")
            self.unique(f"sign{s.id}", f"{key}.id")
            if s.kind not in kinds:
                raise self.err(f"{key}.kind", f"unknown sign kind '{s.kind}' (the kit has "
                               f"{sorted(kinds)})")  # fmt: skip
            by_lane = s.lane is not None and s.along_m is not None and s.position_m is None
            by_pose = s.position_m is not None and s.yaw_deg is not None and s.along_m is None
            if not (by_lane or by_pose):
                raise self.err(key, "give lane and along_m, or position_m and yaw_deg")
            if s.lane is not None and s.lane not in lanes:
                raise self.err(f"{key}.lane", f"no lane '{s.lane}'")
            if (s.kind == "speed_limit") != (s.speed_limit_m_s is not None):
                raise self.err(
                    f"{key}.speed_limit_m_s", "a speed_limit sign needs one, other kinds have none"
                )
            if s.speed_limit_m_s is not None:
                self.positive(s.speed_limit_m_s, f"{key}.speed_limit_m_s")
        for i, placed in enumerate(self.m.placed_signs()):
            self.on_floor([placed.position_m], f"signs[{i}].position_m")

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
        for i, s in enumerate(self.m.slots()):
            key = f"parking_slots[{i}]" if i < len(self.m.parking_slots) else f"tile slot {s.name}"
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

    def markings(self) -> None:
        lanes = {lane.name for lane in self.m.lanes()}
        for i, mk in enumerate(self.m.markings):
            key = f"markings[{i}]"
            self.unique(mk.name, f"{key}.name")
            self.positive(mk.width_m, f"{key}.width_m")
            if not mk.strokes:
                raise self.err(f"{key}.strokes", "a marking needs at least one stroke")
            for j, stroke in enumerate(mk.strokes):
                if len(stroke) < 2:
                    raise self.err(f"{key}.strokes[{j}]", "a stroke needs at least 2 points")
                self.on_floor(stroke, f"{key}.strokes[{j}]")
            if (mk.kind == "broken") != (mk.dash_m is not None):
                raise self.err(f"{key}.dash_m", "give it for a broken marking, and only then")
            if mk.dash_m is not None:
                self.positive(mk.dash_m, f"{key}.dash_m")
            if mk.lane is not None and mk.lane not in lanes:
                raise self.err(f"{key}.lane", f"no lane '{mk.lane}'")
            if (mk.lane is None) != (mk.side is None):
                raise self.err(f"{key}.side", "give lane and side together")

    def stop_lines(self) -> None:
        lanes = {lane.name: lane for lane in self.m.lanes()}
        for i, s in enumerate(self.m.stop_lines):
            key = f"stop_lines[{i}]"
            self.unique(s.name, f"{key}.name")
            self.positive(s.length_m, f"{key}.length_m")
            if s.lane not in lanes:
                raise self.err(f"{key}.lane", f"no lane '{s.lane}' (lanes: {sorted(lanes)[:12]})")
            d, _ = geometry.nearest_on_polyline(
                s.centre_m, geometry.centre_line(lanes[s.lane], 0.01)
            )
            if d > ON_LANE_TOLERANCE_M:
                raise self.err(f"{key}.centre_m", f"{d:.3f} m off lane '{s.lane}' centre line")
