"""The maps' facts the environments need, from the one map description: routes (the MJCF
numerics of the maps contract when the map has them, else the sidecar's lanes), spawn poses
and parking slot goals."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from autodrive.core.settings import settings

MAPS_DIR = settings().maps_dir
INTERSECTION_MAP = "intersection_school"
FALLBACK_MULTI_MAP = "parking_school"  # until Intersection School exists

Pose = tuple[float, float, float]  # x [m], y [m], yaw [rad] of base_link


@dataclass(frozen=True)
class Route:
    name: str
    points_m: npt.NDArray[np.float64]  # (n, 2) in driving order
    half_width_m: float
    loop: bool

    def pose_at(self, i: int, lateral_m: float = 0.0, yaw_offset_rad: float = 0.0) -> Pose:
        """base_link on point i (shifted lateral_m to the left), heading along the route."""
        n = len(self.points_m)
        a, b = self.points_m[i % n], self.points_m[(i + 1) % n]
        yaw = math.atan2(b[1] - a[1], b[0] - a[0])
        return (
            float(a[0] - lateral_m * math.sin(yaw)),
            float(a[1] + lateral_m * math.cos(yaw)),
            yaw + yaw_offset_rad,
        )


def sidecar(map_name: str) -> dict[str, Any]:
    """The map's generated JSON sidecar."""
    path = MAPS_DIR / f"{map_name}.json"
    if not path.is_file():
        raise FileNotFoundError(f"map '{map_name}': no sidecar {path} (run tools/gen-maps)")
    data: dict[str, Any] = json.loads(path.read_text())
    return data


def map_exists(map_name: str) -> bool:
    return (MAPS_DIR / f"{map_name}.xml").is_file()


def route(map_name: str, name: str) -> Route:
    """Route name of the map: its "routes" entry, else the lane of that name (half width: the
    lane's, else a quarter of its two-lane road's width)."""
    side = sidecar(map_name)
    for r in side.get("routes", []):
        if r["name"] == name:
            pts = np.asarray(r["polyline_m"], dtype=np.float64)
            return Route(name, pts, float(r["half_width_m"]), bool(r["loop"]))
    roads = {r["name"]: r for r in side.get("roads", [])}
    for lane in side.get("lanes", []):
        if lane["name"] == name:
            pts = np.asarray([[p["x_m"], p["y_m"]] for p in lane["centre_line"]], dtype=np.float64)
            hw = lane.get("half_width_m") or 0.25 * float(roads[lane["road"]]["width_m"])
            loop = bool(np.hypot(*(pts[0] - pts[-1])) < 0.1)
            return Route(name, pts, float(hw), loop)
    known = [r["name"] for r in side.get("routes", [])] + [ln["name"] for ln in side["lanes"]]
    raise ValueError(f"map '{map_name}' has no route or lane '{name}' (has: {', '.join(known)})")


def routes(map_name: str) -> list[str]:
    """The map's route names (the contract's "routes"), [] when it has none."""
    return [str(r["name"]) for r in sidecar(map_name).get("routes", [])]


def route_start(map_name: str, name: str) -> Pose | None:
    for r in sidecar(map_name).get("routes", []):
        if r["name"] == name and "start" in r:
            s = r["start"]
            return (float(s["x_m"]), float(s["y_m"]), float(s["yaw_rad"]))
    return None


def spawn(map_name: str) -> Pose:
    s = sidecar(map_name)["spawn"]
    return (float(s["x_m"]), float(s["y_m"]), float(s["yaw_rad"]))


def multi_car_map() -> str:
    return INTERSECTION_MAP if map_exists(INTERSECTION_MAP) else FALLBACK_MULTI_MAP


def file_of(map_name: str) -> Path:
    return MAPS_DIR / f"{map_name}.xml"
