"""Writes a map's JSON sidecar (maps/<map>.json beside its MJCF) for C and C++
readers: everything in the description and the kit, in SI units (m, rad), names as in the MJCF,
plus each lane's sampled centre line and each slot's corners."""

from __future__ import annotations

import json
import math
from typing import Any

from autodrive.maps import reftags
from autodrive.maps.description import MapDescription
from autodrive.maps.model import Piece, Vec2

CENTRE_LINE_STEP_M = 0.05  # spacing of the sampled lane centre lines in the sidecar


def _xy(p: Vec2) -> list[float]:
    return [p[0], p[1]]


def _r(v: float) -> float:
    return round(v, 9)  # no float noise (1e-17) in a human-readable file


def document(m: MapDescription) -> dict[str, Any]:
    """The sidecar's content as plain JSON types."""
    kit = m.kit
    sp = m.spawn_pose()
    doc: dict[str, Any] = {
        "name": m.name,
        "generated_from": [f"{m.name}.yaml", "kit.yaml"],
        "floor": {
            "half_size_m": m.floor_half_size_m,
            "surface": m.floor_surface,
            "friction": kit.surfaces[m.floor_surface].friction,
        },
        "surfaces": {n: {"friction": s.friction} for n, s in kit.surfaces.items()},
        "spawn": {"x_m": sp.x_m, "y_m": sp.y_m, "yaw_rad": _r(sp.yaw_rad)},
        "terrain_patches": [
            {
                "name": p.name,
                "surface": p.surface,
                "friction": kit.surfaces[p.surface].friction,
                "centre_m": _xy(p.centre_m),
                "size_m": _xy(p.size_m),
            }
            for p in m.terrain_patches
        ],
        "walls": [
            {
                "name": w.name,
                "face_centre_m": _xy(w.face_centre_m),
                "normal": _xy(w.normal),
                "length_m": w.length_m,
                "height_m": kit.obstacle.wall_height_m,
            }
            for w in m.walls
        ],
        "boxes": [
            {
                "name": b.name,
                "centre_m": _xy(b.centre_m),
                "size_m": list(b.size_m),
                "yaw_rad": b.yaw_rad,
            }
            for b in m.boxes
        ],
        "cones": [
            {
                "name": c.name,
                "position_m": _xy(c.position_m),
                "radius_m": kit.cone.radius_m,
                "height_m": kit.cone.height_m,
            }
            for c in m.cones
        ],
        "parking_slots": [
            {
                "name": s.name,
                "centre_m": _xy(s.centre_m),
                "yaw_rad": _r(s.yaw_rad),
                "width_m": s.size_m[0],
                "depth_m": s.size_m[1],
                "corners_m": [[_r(x), _r(y)] for x, y in s.corners_m()],
            }
            for s in m.slots()
        ],
        "roads": [
            {
                "name": r.name,
                "width_m": r.width_m,
                "centre_marking": r.centre_marking,
                "pieces": [_piece(p) for p in r.pieces],
                "lanes": [lane.name for lane in r.lanes],
            }
            for r in m.roads
        ],
        "lanes": [
            {
                "name": lane.name,
                "road": lane.road.name,
                "offset_m": lane.offset_m,
                "direction": lane.direction,
                "half_width_m": _r(lane.half_width_m),
                "centre_line_step_m": CENTRE_LINE_STEP_M,
                "centre_line": [
                    {"x_m": _r(x), "y_m": _r(y), "heading_rad": _r(h)}
                    for x, y, h in m.centre_line(lane, CENTRE_LINE_STEP_M)
                ],
            }
            for lane in m.lanes()
        ],
        "stop_lines": [
            {
                "name": s.name,
                "lane": s.lane,
                "centre_m": _xy(s.centre_m),
                "length_m": s.length_m,
                "yaw_rad": _r(m.stop_line_yaw_rad(s)),
            }
            for s in m.all_stop_lines()
        ],
        "traffic_lights": [
            {
                "id": t.id,
                "name": t.name,
                "position_m": [_r(t.position_m[0]), _r(t.position_m[1])],
                "yaw_rad": _r(t.yaw_rad),
                "lane": t.lane,
                "stop_line": t.stop_line,
                "program": {
                    "cycle_s": t.program.cycle_s,
                    "offset_s": t.program.offset_s,
                    "green_s": t.program.green_s,
                    "yellow_s": t.program.yellow_s,
                },
            }
            for t in m.lights()
        ],
        "light_conflicts": [list(p) for p in m.light_conflicts()],
        "signs": [
            {
                "id": s.id,
                "name": s.name,
                "kind": s.kind,
                "category": kit.sign.kinds[s.kind].category,
                "meaning": kit.sign.kinds[s.kind].meaning,
                "position_m": [_r(s.position_m[0]), _r(s.position_m[1])],
                "yaw_rad": _r(s.yaw_rad),
                "lane": s.lane,
                "speed_limit_m_s": s.speed_limit_m_s,
            }
            for s in m.placed_signs()
        ],
        "tiles": [
            {
                "name": t.spec.name,
                "type": t.spec.type,
                "lanes": t.spec.lanes,
                "centre_m": _xy(t.spec.centre_m),
                "rotation_rad": _r(math.radians(t.spec.rotation_deg)),
                "size_m": t.size_m,
                "road_width_m": _r(t.road_width_m),
            }
            for t in m.tile_contents()
        ],
        "routes": [
            {
                "name": r.name,
                "lanes": r.lanes,
                "loop": r.loop,
                "start": {
                    "x_m": _r(r.start.x_m),
                    "y_m": _r(r.start.y_m),
                    "yaw_rad": _r(r.start.yaw_rad),
                },
                "length_m": _r(r.length_m),
                "half_width_m": _r(r.half_width_m),
                "polyline_m": [[_r(x), _r(y)] for x, y in r.polyline_m],
            }
            for r in m.named_routes()
        ],
        "spawns": [
            {
                "name": s.name,
                "x_m": s.pose.x_m,
                "y_m": s.pose.y_m,
                "yaw_rad": s.pose.yaw_rad,
                "route": s.route,
            }
            for s in m.named_spawns()
        ],
        "parked": [
            {"slot": p.slot, "name": f"parked_{p.slot}", "size_m": list(kit.parked_car_size_m)}
            for p in m.parked
        ],
        "eye_cameras": [
            {
                "name": c.name,
                "centre_m": _xy(c.centre_m),
                "height_m": c.height_m,
                "fovy_deg": kit.eye_camera.fovy_deg,
                "width_px": kit.eye_camera.width_px,
                "height_px": kit.eye_camera.height_px,
            }
            for c in m.eye_cameras
        ],
        "late_obstacles": [
            {
                "name": o.name,
                "centre_m": _xy(o.centre_m),
                "size_m": list(o.size_m),
                "yaw_rad": o.yaw_rad,
                "appear_s": o.appear_s,
                "trigger_radius_m": o.trigger_radius_m,
            }
            for o in m.late_obstacles
        ],
        "options": {"light_level": m.options.light_level},
    }
    if m.reference_tags:  # only on maps that have them: the others' sidecars stay as they were
        doc["reference_tags"] = reftags.sidecar(m.reference_tags)
    if m.imported_from is not None:  # only on imported maps (tools/map import)
        f = m.imported_from
        doc["imported_from"] = {"file": f.file, "scale": f.scale, "offset_m": _xy(f.offset_m),
                                "opendrive_version": f.opendrive_version, "warnings": f.warnings,
                                "unsupported_signals": f.unsupported_signals,
                                "signal_lights": f.signal_lights}  # fmt: skip
    return doc


def _piece(p: Piece) -> dict[str, Any]:
    if p.line is not None:
        return {"name": p.name, "line": {"from_m": _xy(p.line.from_m), "to_m": _xy(p.line.to_m)}}
    assert p.arc is not None
    return {
        "name": p.name,
        "arc": {
            "centre_m": _xy(p.arc.centre_m),
            "radius_m": p.arc.radius_m,
            "start_rad": _r(math.radians(p.arc.start_deg)),
            "sweep_rad": _r(math.radians(p.arc.sweep_deg)),
        },
    }


def _scalar(v: Any) -> bool:
    return not isinstance(v, (dict, list))


def _dump(v: Any, indent: str = "") -> str:
    """JSON with one line per leaf object or number list (a lane point, a corner), so that the
    file stays short and diffs stay readable."""
    inner = indent + " "
    if isinstance(v, dict):
        if (
            all(_scalar(x) or (isinstance(x, list) and all(map(_scalar, x))) for x in v.values())
            and len(v) <= 6
            and indent
        ):
            return json.dumps(v, separators=(", ", ": "))
        items = [f"{inner}{json.dumps(k)}: {_dump(x, inner)}" for k, x in v.items()]
        return "{\n" + ",\n".join(items) + "\n" + indent + "}" if items else "{}"
    if isinstance(v, list):
        if all(map(_scalar, v)):
            return json.dumps(v, separators=(", ", ": "))
        return "[\n" + ",\n".join(inner + _dump(x, inner) for x in v) + "\n" + indent + "]"
    return json.dumps(v)


def generate(m: MapDescription) -> str:
    """The sidecar's text."""
    return _dump(document(m)) + "\n"
