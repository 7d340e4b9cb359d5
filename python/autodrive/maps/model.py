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
    yellow_rgba: Rgba  # a yellow marking's (the rest are rgba's white)


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
    width_px: int  # every overhead camera's image (the map's 'eye' and its eye_cameras)
    height_px: int


@dataclass(frozen=True)
class TileKit:
    """The road kit's tiles: sizes, lane widths and how their textures are painted."""

    lane_width_m: float
    shoulder_m: float
    cell_m: dict[str, float]  # per lane count ("1", "2", "4", "6"): side of a one-cell tile
    height_m: float
    thickness_m: float
    texture_px_per_m: float
    asphalt_rgb: Vec3
    verge_rgb: Vec3
    line_rgb: Vec3
    centre_rgb: Vec3
    paint_width_m: float
    stop_line_width_m: float
    stop_line_setback_m: float
    dash_length_m: float
    dash_gap_m: float
    dead_end_margin_m: float
    lot_slot_m: Vec2  # perpendicular lot slot: width across, depth
    roadside_slot_m: Vec2  # parallel roadside slot: width across, length along
    roadside_clearance_m: float  # kerb to the pole of a light or the post of a sign


@dataclass(frozen=True)
class TrafficLightKit:
    pole_radius_m: float
    pole_height_m: float
    pole_rgba: Rgba
    housing_size_m: Vec3  # full depth, width, height
    housing_rgba: Rgba
    lamp_radius_m: float
    lamp_off_rgba: dict[str, Rgba]  # red, yellow, green: the dark (off) look
    min_all_red_s: float


@dataclass(frozen=True)
class SignKindKit:
    category: Literal["regulatory", "cautionary", "informatory"]
    meaning: str
    shape: Literal["octagon", "triangle_down", "triangle_up", "circle", "square", "diamond"]
    rgb: Vec3  # the face's main colour
    symbol: Literal["text", "curve_left", "curve_right", "bar", "p", "walker", "none"]
    text: str = ""


@dataclass(frozen=True)
class SignKit:
    post_radius_m: float
    post_height_m: float
    post_rgba: Rgba
    face_size_m: float
    face_thickness_m: float
    texture_px: int
    kinds: dict[str, SignKindKit]


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
    tiles: TileKit
    traffic_light: TrafficLightKit
    sign: SignKit
    parked_car_size_m: Vec3  # a parked car stand-in (box) in a slot: length, width, height
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
class Marking:
    """A painted line on the floor (an imported OpenDRIVE roadMark line): its strokes, each a
    stretch painted without a break (a solid line has one, a broken line one per dash), as
    polylines of the line's middle [m], width_m across. For the export: kind and dash_m (a broken
    line's dash and space [m]), and the lane whose border it paints, on which side of its traffic,
    offset_m from that border to the lane's left [m]."""

    name: str
    kind: Literal["solid", "broken"]
    colour: Literal["white", "yellow"]
    width_m: float
    strokes: list[list[Vec2]]
    dash_m: Optional[Vec2] = None
    lane: Optional[str] = None
    side: Optional[Literal["left", "right"]] = None
    offset_m: float = 0.0


@dataclass(frozen=True)
class Lane:
    """A lane with its road: its centre line runs offset_m left of the road's forward line.
    half_width_m: half the lane's width; kerb_right_m: from its centre line to the road's edge on
    its right (where lights and signs stand)."""

    name: str
    road: Road
    offset_m: float
    direction: Literal["forward", "backward"]
    half_width_m: float = 0.0
    kerb_right_m: float = 0.0


@dataclass(frozen=True)
class StopLine:
    name: str
    lane: str
    centre_m: Vec2
    length_m: float


@dataclass(frozen=True)
class Program:
    """A light's fixed-time program: u = (t - offset_s) mod cycle_s; green while u < green_s,
    yellow until green_s + yellow_s, red for the rest."""

    cycle_s: float
    offset_s: float
    green_s: float
    yellow_s: float


@dataclass(frozen=True)
class TrafficLightSpec:
    """A light at a stop line; it stands on the kerb right of the stop line's lane, facing the
    approach, unless position_m and yaw_deg (the way its lamps face) are given. crosses: the
    lights whose approaches cross this one's where no tile says so (an imported junction)."""

    id: int
    stop_line: str
    program: Program
    position_m: Optional[Vec2] = None
    yaw_deg: Optional[float] = None
    crosses: list[int] = field(default_factory=list)


@dataclass(frozen=True)
class SignSpec:
    """A sign beside a lane (lane + along_m: on its right kerb, facing its traffic) or at a
    pose (position_m + yaw_deg: the way its face points)."""

    id: int
    kind: str
    lane: Optional[str] = None
    along_m: Optional[float] = None
    position_m: Optional[Vec2] = None
    yaw_deg: Optional[float] = None
    speed_limit_m_s: Optional[float] = None


@dataclass(frozen=True)
class TileSpec:
    """A road-kit tile: its type, lane count, centre and rotation (counter-clockwise, a multiple
    of 90 deg). Unrotated, a straight runs west-east, a curve joins west and south, a dead end,
    parking lot and 3-way intersection open to the west (the 3-way also east and south)."""

    name: str
    type: Literal[
        "straight", "curve", "dead_end", "tee", "cross", "parking_lot", "roadside_parking", "patch"
    ]
    lanes: int
    centre_m: Vec2
    rotation_deg: float = 0.0


@dataclass(frozen=True)
class RouteSpec:
    """A named route: lanes driven one after another (each ends where the next starts)."""

    name: str
    lanes: list[str]
    loop: bool = False


@dataclass(frozen=True)
class SpawnSpec:
    """A named start: along_m along a route, or at position_m / yaw_deg."""

    name: str
    route: Optional[str] = None
    along_m: Optional[float] = None
    position_m: Optional[Vec2] = None
    yaw_deg: Optional[float] = None


@dataclass(frozen=True)
class Parked:
    """A stand-in for a parked car (a box of the kit's parked car size) in a slot."""

    slot: str


@dataclass(frozen=True)
class LateObstacle:
    """A box that appears at appear_s [s] of sim time, or when a car comes within
    trigger_radius_m of it (whichever is given)."""

    name: str
    centre_m: Vec2
    size_m: Vec3
    yaw_rad: float = 0.0
    appear_s: Optional[float] = None
    trigger_radius_m: Optional[float] = None


@dataclass(frozen=True)
class EyeCameraSpec:
    """One of a map's several overhead cameras: straight down from height_m above centre_m,
    image up = map +y, the kit's fovy and image size. Its channels are <CAM>_IMAGE and
    <CAM>_CAMERA_INFO with <CAM> = the name in capitals."""

    name: str
    centre_m: Vec2
    height_m: float


@dataclass(frozen=True)
class ReferenceTagSpec:
    """A tag36h11 print lying on the map at a known place, for `autodrive-eye calibrate-map` of
    the overhead cameras (shared by neighbours where they overlap): its black square's edge
    size_m, its centre, the top of the print towards yaw_deg (from map +x). Visual only, on a
    plate just above the tiles (REFERENCE_TAG_TOP_M)."""

    id: int
    centre_m: Vec2
    yaw_deg: float
    size_m: float


# A reference tag's plate: top face above the floor (over the tiles' 0.5 mm and the terrain
# patches' 1 mm) and thickness [m]; the top face is the tag's plane (z_m in the sidecar).
REFERENCE_TAG_TOP_M = 0.002
REFERENCE_TAG_THICKNESS_M = 0.001


@dataclass(frozen=True)
class Options:
    light_level: float = 1.0  # 0 (night) .. 1 (day)


@dataclass(frozen=True)
class ImportedFrom:
    """Where an imported map came from (tools/map import): a point of the file maps to ours as
    ours = scale * file + offset_m [m]; what the import could not carry over is listed."""

    file: str
    scale: float
    offset_m: Vec2
    opendrive_version: str
    warnings: list[str] = field(default_factory=list)
    unsupported_signals: list[str] = field(default_factory=list)
    signal_lights: dict[str, list[int]] = field(default_factory=dict)  # signal id -> light ids


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
    traffic_lights: list[TrafficLightSpec]
    signs: list[SignSpec]
    options: Options = Options()
    tiles: list[TileSpec] = field(default_factory=list)
    routes: list[RouteSpec] = field(default_factory=list)
    spawns: list[SpawnSpec] = field(default_factory=list)
    parked: list[Parked] = field(default_factory=list)
    late_obstacles: list[LateObstacle] = field(default_factory=list)
    eye_cameras: list[EyeCameraSpec] = field(default_factory=list)
    reference_tags: list[ReferenceTagSpec] = field(default_factory=list)
    markings: list[Marking] = field(default_factory=list)
    imported_from: Optional[ImportedFrom] = None


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
