"""Health (no login), the map for drawing, the live state and the signs."""

from __future__ import annotations

import math
from typing import Any

from fastapi import APIRouter

from autodrive.core import vehicle
from autodrive.scm.api.deps import MapPayload, ScmDep, Viewer
from autodrive.scm.service import Scm

router = APIRouter(prefix="/api", tags=["state"])


def map_payload(scm: Scm) -> dict[str, Any]:
    """The map for drawing (GET /api/map): lanes thinned to ~40 points, stop lines as
    segments, lights, signs, conflicts and the car's footprint."""
    m = scm.map
    lanes = []
    for name, g in scm.roadnet.lanes.items():
        step = max(1, len(g.pts) // 40)
        pts = g.pts[::step, :2].round(3).tolist()
        if len(g.pts) % step != 1:
            pts.append(g.pts[-1, :2].round(3).tolist())
        lanes.append({"name": name, "half_width_m": g.half_width_m, "points": pts})
    stops = []
    for s in m.all_stop_lines():
        yaw = m.stop_line_yaw_rad(s)
        h = s.length_m / 2
        c = s.centre_m
        stops.append(
            {
                "name": s.name,
                "from": [c[0] - h * math.cos(yaw), c[1] - h * math.sin(yaw)],
                "to": [c[0] + h * math.cos(yaw), c[1] + h * math.sin(yaw)],
            }
        )
    v = vehicle.load()
    return {
        "name": m.name,
        "half_size_m": m.floor_half_size_m,
        "lanes": lanes,
        "stop_lines": stops,
        "lights": [
            {
                "id": t.id,
                "x_m": t.position_m[0],
                "y_m": t.position_m[1],
                "yaw_rad": t.yaw_rad,
                "stop_line": t.stop_line,
            }
            for t in m.lights()
        ],
        "signs": [
            {
                "id": s.id,
                "kind": s.kind,
                "x_m": s.position_m[0],
                "y_m": s.position_m[1],
                "yaw_rad": s.yaw_rad,
                "speed_limit_m_s": s.speed_limit_m_s,
            }
            for s in m.placed_signs()
        ],
        "conflicts": m.light_conflicts(),
        # the map's tiles that hold lights: a junction's name, kind and place, as the map says
        "junctions": [
            {"name": t.name, "type": t.type, "centre_m": list(t.centre_m)}
            for t in m.tiles
            if t.name in {j for j in scm.controller.junctions}
        ],
        "footprint": {
            "length_m": v.envelope_length_m,
            "width_m": v.envelope_width_m,
            "centre_ahead_m": v.envelope_center_ahead_m,
        },
    }


@router.get("/status")
def status(scm: ScmDep) -> dict[str, Any]:
    """Health, no login needed: ready (the LCM threads, the pose receiver process and
    the database writer all run: what tools/demo waits for), counters of the LCM and
    database sides."""
    snap = scm.snapshot()
    return {"ok": True, "ready": scm.ready(), "map": scm.map.name, "stats": snap["stats"]}


@router.get("/map")
def get_map(_: Viewer, payload: MapPayload) -> dict[str, Any]:
    """Lanes, stop lines, lights, signs, conflicts and the car's footprint, for drawing."""
    return payload


@router.get("/state")
def get_state(_: Viewer, scm: ScmDep) -> dict[str, Any]:
    """Everything live: vehicles, lights, junctions, the last events, counters."""
    return scm.snapshot()


@router.get("/signs")
def signs(_: Viewer, payload: MapPayload) -> list[dict[str, Any]]:
    return list(payload["signs"])
