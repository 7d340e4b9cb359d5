"""The map description's types: one dataclass per YAML mapping, field names = YAML keys (units in
the names). The loader (loader.py) builds them strictly from these field types."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal, Optional

Vec2 = tuple[float, float]
Vec3 = tuple[float, float, float]
Rgba = tuple[float, float, float, float]


class MapDescriptionError(ValueError):
    """A map description that cannot be used; the message names the file and the dotted key."""


@dataclass(frozen=True)
class Pose:
    """A planar pose in the map's world frame [m, m, rad]."""

    x_m: float
    y_m: float
    yaw_rad: float


# --- the kit (kit.yaml) ---------------------------------------------------------------------


@dataclass(frozen=True)
class Surface:
    friction: float
    rgba: Rgba


@dataclass(frozen=True)
class ContactKit:
    torsional_friction_m: float
    rolling_friction_m: float


@dataclass(frozen=True)
class ObstacleKit:
    friction: float
    box_rgba: Rgba
    wall_rgba: Rgba
    wall_height_m: float


@dataclass(frozen=True)
class ConeKit:
    radius_m: float
    height_m: float
    rgba: Rgba
    base_size_m: float
    base_thickness_m: float
    base_rgba: Rgba


@dataclass(frozen=True)
class MarkingKit:
    line_width_m: float
    stop_line_width_m: float
    centre_dash_width_m: float
    centre_dash_length_m: float
    centre_dash_pitch_m: float
    height_m: float
    thickness_m: float
    rgba: Rgba


@dataclass(frozen=True)
class RoadKit:
    height_m: float
    thickness_m: float
    rgba: Rgba
    arc_segments_per_90deg: int
    arc_segment_overlap: float


@dataclass(frozen=True)
class EyeCameraKit:
    height_m: float
    fovy_deg: float


@dataclass(frozen=True)
class Kit:
    """Materials, markings and props shared by every map (maps/kit.yaml)."""

    surfaces: dict[str, Surface]
    contact: ContactKit
    terrain_patch_thickness_m: float
    obstacle: ObstacleKit
    cone: ConeKit
    marking: MarkingKit
    road: RoadKit
    eye_camera: EyeCameraKit
    source: Path = Path()


# --- a map (<map>.yaml) ---------------------------------------------------------------------


@dataclass(frozen=True)
class Spawn:
    position_m: Vec2
    yaw_deg: float

    @property
    def pose(self) -> Pose:
        return Pose(self.position_m[0], self.position_m[1], math.radians(self.yaw_deg))


@dataclass(frozen=True)
class TerrainPatch:
    name: str
    surface: str
    centre_m: Vec2
    size_m: Vec2


@dataclass(frozen=True)
class Wall:
    """A boundary wall, simulated as a plane: nothing can be behind it."""

    name: str
    face_centre_m: Vec2
    normal: Vec2
    length_m: float


@dataclass(frozen=True)
class Box:
    name: str
    centre_m: Vec2
    size_m: Vec3
    yaw_rad: float


@dataclass(frozen=True)
class Cone:
    name: str
    position_m: Vec2


@dataclass(frozen=True)
class ParkingSlot:
    """A marked slot; yaw_deg is the heading of a car parked forward-in, size_m is (width
    across, depth along the yaw)."""

    name: str
    centre_m: Vec2
    yaw_deg: float
    size_m: Vec2

    @property
    def yaw_rad(self) -> float:
        return math.radians(self.yaw_deg)

    def corners_m(self) -> list[Vec2]:
        return rect_corners(self.centre_m, (self.size_m[1], self.size_m[0]), self.yaw_rad)


@dataclass(frozen=True)
class Line:
    from_m: Vec2
    to_m: Vec2


@dataclass(frozen=True)
class Arc:
    centre_m: Vec2
    radius_m: float
    start_deg: float
    sweep_deg: float


@dataclass(frozen=True)
class Piece:
    """One piece of a road: exactly one of line and arc."""

    name: str
    line: Optional[Line] = None
    arc: Optional[Arc] = None


@dataclass(frozen=True)
class LaneSpec:
    name: str
    offset_m: float
    direction: Literal["forward", "backward"]


@dataclass(frozen=True)
class Road:
    name: str
    width_m: float
    centre_marking: Literal["dashed", "none"]
    pieces: list[Piece]
    lanes: list[LaneSpec]


@dataclass(frozen=True)
class Lane:
    """A lane with its road: its centre line runs offset_m left of the road's forward line."""

    name: str
    road: Road
    offset_m: float
    direction: Literal["forward", "backward"]


@dataclass(frozen=True)
class StopLine:
    name: str
    lane: str
    centre_m: Vec2
    length_m: float


@dataclass(frozen=True)
class Fixture:
    """A traffic light or sign (filled by a later issue)."""

    id: str
    position_m: Vec2
    yaw_deg: float


@dataclass(frozen=True)
class MapFile:
    """Exactly the keys of a <map>.yaml."""

    floor_half_size_m: float
    floor_surface: str
    spawn: Spawn
    terrain_patches: list[TerrainPatch]
    walls: list[Wall]
    boxes: list[Box]
    cones: list[Cone]
    parking_slots: list[ParkingSlot]
    roads: list[Road]
    stop_lines: list[StopLine]
    traffic_lights: list[Fixture]
    signs: list[Fixture]


@dataclass(frozen=True)
class Rect:
    """An obstacle's footprint as a rectangle: centre, half sizes, yaw [m, m, m, m, rad]."""

    x_m: float
    y_m: float
    half_x_m: float
    half_y_m: float
    yaw_rad: float


def rect_corners(centre: Vec2, size: Vec2, yaw_rad: float) -> list[Vec2]:
    """Corners of a rectangle of full size (along yaw, across) centred at centre."""
    c, s = math.cos(yaw_rad), math.sin(yaw_rad)
    hx, hy = size[0] / 2, size[1] / 2
    return [
        (centre[0] + c * dx - s * dy, centre[1] + s * dx + c * dy)
        for dx, dy in ((hx, hy), (-hx, hy), (-hx, -hy), (hx, -hy))
    ]
