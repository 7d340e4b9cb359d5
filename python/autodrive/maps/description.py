"""MapDescription: one loaded map (its description plus the kit) and the questions tools ask it."""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Literal, Union

from autodrive.maps import geometry, tiles
from autodrive.core.geometry import wrap
from autodrive.maps.model import (
    Kit,
    Lane,
    MapDescriptionError,
    MapFile,
    ParkingSlot,
    Pose,
    Program,
    Rect,
)
from autodrive.maps.model import Road, StopLine, Vec2


@dataclass(frozen=True)
class TrafficLight:
    """A light placed: tl<id> in the MJCF; yaw_rad is the way its lamps face."""

    id: int
    name: str
    position_m: Vec2
    yaw_rad: float
    lane: str
    stop_line: str
    program: Program


@dataclass(frozen=True)
class Sign:
    """A sign placed: sign<id> in the MJCF; yaw_rad is the way its face points."""

    id: int
    name: str
    kind: str
    position_m: Vec2
    yaw_rad: float
    lane: str | None
    speed_limit_m_s: float | None


@dataclass(frozen=True)
class Route:
    """A named route: its lanes' centre lines joined, in driving order, <= 0.05 m apart."""

    name: str
    lanes: list[str]
    loop: bool
    polyline_m: list[Vec2]
    half_width_m: float

    @property
    def start(self) -> Pose:
        (x0, y0), (x1, y1) = self.polyline_m[0], self.polyline_m[1]
        return Pose(x0, y0, math.atan2(y1 - y0, x1 - x0))

    def pose_at(self, along_m: float) -> Pose:
        """The point along_m along the route and its heading [m, m, rad]."""
        left = along_m
        for a, b in zip(self.polyline_m, self.polyline_m[1:]):
            seg = math.dist(a, b)
            if left <= seg or b is self.polyline_m[-1]:
                t = min(1.0, left / seg) if seg > 0 else 0.0
                return Pose(a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]),
                            math.atan2(b[1] - a[1], b[0] - a[0]))  # fmt: skip
            left -= seg
        raise MapDescriptionError(f"route '{self.name}' is empty")  # pragma: no cover

    @property
    def length_m(self) -> float:
        return sum(math.dist(a, b) for a, b in zip(self.polyline_m, self.polyline_m[1:]))

    def reversed(self) -> Route:
        """The same centre line driven the other way (its points in reverse order), named
        NAME:reversed. Not a lane of the map's traffic: on a two-lane road it is the wrong side."""
        return Route(f"{self.name}:reversed", self.lanes[::-1], self.loop,
                     self.polyline_m[::-1], self.half_width_m)  # fmt: skip


@dataclass(frozen=True)
class NamedSpawn:
    name: str
    pose: Pose
    route: str | None


if TYPE_CHECKING:
    from autodrive.core.vehicle import Vehicle


@dataclass(frozen=True, kw_only=True)
class MapDescription(MapFile):
    """A map as described in maps/<name>.yaml, with the kit it is built from."""

    name: str
    source: Path
    kit: Kit

    # --- poses and places ---------------------------------------------------------------------

    def spawn_pose(self) -> Pose:
        """Car 1's default start pose (the MJCF 'spawn' site) [m, m, rad]."""
        return self.spawn.pose

    def slots(self) -> list[ParkingSlot]:
        """Every parking slot: the description's own, then those of its tiles."""
        return list(self.parking_slots) + [s for t in self.tile_contents() for s in t.slots]

    def slot(self, key: Union[str, int]) -> ParkingSlot:
        """A parking slot by name ('s2') or by index in slots() (2)."""
        slots = self.slots()
        if isinstance(key, int) and not isinstance(key, bool):
            if not 0 <= key < len(slots):
                raise MapDescriptionError(
                    f"{self.source}: parking_slots: no slot {key} (the map has "
                    f"{len(slots)}: 0..{len(slots) - 1})"
                )
            return slots[key]
        for s in slots:
            if s.name == key:
                return s
        names = [s.name for s in slots]
        raise MapDescriptionError(f"{self.source}: parking_slots: no slot '{key}' (has {names})")

    def slot_goal(
        self,
        slot: Union[ParkingSlot, str, int],
        vehicle: "Vehicle",
        direction: Literal["forward", "reverse"] = "forward",
    ) -> Pose:
        """Goal pose of the car's base_link (rear axle centre) parked in the slot, the car's
        envelope centred in it: facing the slot's yaw (forward-in) or away from it (reverse)."""
        s = slot if isinstance(slot, ParkingSlot) else self.slot(slot)
        yaw = s.yaw_rad if direction == "forward" else s.yaw_rad + math.pi
        ahead = vehicle.envelope_center_ahead_m
        yaw = wrap(yaw)
        return Pose(
            s.centre_m[0] - ahead * math.cos(yaw), s.centre_m[1] - ahead * math.sin(yaw), yaw
        )

    def obstacles(self) -> list[Rect]:
        """Collidable props (boxes, cones, traffic light poles and sign posts as their bounding
        squares, parked cars) as footprint rectangles; walls are not included (see walls)."""
        out = [
            Rect(b.centre_m[0], b.centre_m[1], b.size_m[0] / 2, b.size_m[1] / 2, b.yaw_rad)
            for b in self.boxes
        ]
        r = self.kit.cone.radius_m
        out += [Rect(c.position_m[0], c.position_m[1], r, r, 0.0) for c in self.cones]
        r = self.kit.traffic_light.pole_radius_m
        out += [Rect(t.position_m[0], t.position_m[1], r, r, 0.0) for t in self.lights()]
        r = self.kit.sign.post_radius_m
        out += [Rect(s.position_m[0], s.position_m[1], r, r, 0.0) for s in self.placed_signs()]
        length, width, _ = self.kit.parked_car_size_m
        for p in self.parked:
            s = self.slot(p.slot)
            out.append(Rect(s.centre_m[0], s.centre_m[1], length / 2, width / 2, s.yaw_rad))
        return out

    # --- roads ----------------------------------------------------------------------------------

    def tile_contents(self) -> list[tiles.TileContent]:
        """Each tile's lanes, stop lines and slots in the world frame."""
        return self._tiles

    @functools.cached_property
    def _tiles(self) -> list[tiles.TileContent]:
        return [tiles.expand(self.kit.tiles, t) for t in self.tiles]

    def lanes(self) -> list[Lane]:
        """The free-form roads' lanes, then the tiles' (one per movement through a tile)."""
        return self._lanes

    @functools.cached_property
    def _lanes(self) -> list[Lane]:
        out = []
        for r in self.roads:
            half = r.width_m / (2 * max(1, len(r.lanes)))
            for l in r.lanes:
                kerb = r.width_m / 2 + (l.offset_m if l.direction == "forward" else -l.offset_m)
                out.append(Lane(l.name, r, l.offset_m, l.direction, half, kerb))
        return out + [lane for t in self.tile_contents() for lane in t.lanes]

    def all_stop_lines(self) -> list[StopLine]:
        """The description's own stop lines, then the tiles' (painted in their textures)."""
        return list(self.stop_lines) + [s for t in self.tile_contents() for s in t.stop_lines]

    def stop_line(self, name: str) -> StopLine:
        for s in self.all_stop_lines():
            if s.name == name:
                return s
        raise MapDescriptionError(f"{self.source}: no stop line '{name}'")

    def lane(self, name: str) -> Lane:
        for lane in self.lanes():
            if lane.name == name:
                return lane
        names = [lane.name for lane in self.lanes()]
        raise MapDescriptionError(f"{self.source}: roads: no lane '{name}' (has {names})")

    def centre_line(
        self, lane: Union[Lane, str], step_m: float = 0.05
    ) -> list[tuple[float, float, float]]:
        """A lane's centre line as (x, y, heading) points [m, m, rad], step_m apart at most."""
        return geometry.centre_line(lane if isinstance(lane, Lane) else self.lane(lane), step_m)

    # --- traffic elements and routes ------------------------------------------------------------

    def lights(self) -> list[TrafficLight]:
        """The traffic lights, placed (a light without a pose stands on its stop line's kerb)."""
        kerbs = {k: v for t in self.tile_contents() for k, v in t.kerb_of_stop_line.items()}
        out = []
        for spec in self.traffic_lights:
            stop = self.stop_line(spec.stop_line)
            heading = self.stop_line_yaw_rad(stop) - math.pi / 2
            if spec.position_m is not None:
                pos = spec.position_m
            elif stop.name in kerbs:
                pos = kerbs[stop.name]
            else:
                lane = self.lane(stop.lane)
                d = lane.kerb_right_m + self.kit.tiles.roadside_clearance_m
                pos = (stop.centre_m[0] + d * math.sin(heading),
                       stop.centre_m[1] - d * math.cos(heading))  # fmt: skip
            yaw = math.radians(spec.yaw_deg) if spec.yaw_deg is not None else heading + math.pi
            out.append(TrafficLight(spec.id, f"tl{spec.id}", pos, wrap(yaw), stop.lane, stop.name,
                                    spec.program))  # fmt: skip
        return out

    def light_conflicts(self) -> list[tuple[int, int]]:
        """Pairs of lights that must never both show green or yellow: lights at the same
        intersection tile whose approaches cross (not opposite each other), and the pairs the
        description names (traffic_lights[].crosses)."""
        tile_of = {s.name: t.spec.name for t in self.tile_contents() for s in t.stop_lines}
        ls = self.lights()
        out = []
        for i, a in enumerate(ls):
            for b in ls[i + 1 :]:
                if tile_of.get(a.stop_line) is None or tile_of.get(a.stop_line) != tile_of.get(
                    b.stop_line
                ):
                    continue
                dyaw = abs(wrap(a.yaw_rad - b.yaw_rad))
                if 0.1 < dyaw < math.pi - 0.1:
                    out.append((a.id, b.id))
        for spec in self.traffic_lights:  # given by the description (imported junctions)
            for other in spec.crosses:
                pair = (min(spec.id, other), max(spec.id, other))
                if pair not in out:
                    out.append(pair)
        return out

    def placed_signs(self) -> list[Sign]:
        """The signs, placed (a sign given by lane and along_m stands on that lane's kerb)."""
        out = []
        for spec in self.signs:
            if spec.lane is not None and spec.along_m is not None:
                lane = self.lane(spec.lane)
                pts = self.centre_line(lane, 0.01)
                k = min(len(pts) - 1, max(0, round(spec.along_m / 0.01)))
                x, y, h = pts[k]
                d = lane.kerb_right_m + self.kit.tiles.roadside_clearance_m
                pos = (round(x + d * math.sin(h), 9), round(y - d * math.cos(h), 9))
                yaw = h + math.pi
            else:
                assert spec.position_m is not None and spec.yaw_deg is not None
                pos, yaw = spec.position_m, math.radians(spec.yaw_deg)
            out.append(Sign(spec.id, f"sign{spec.id}", spec.kind, pos, wrap(yaw), spec.lane,
                            spec.speed_limit_m_s))  # fmt: skip
        return out

    def route(self, name: str) -> Route:
        for r in self.named_routes():
            if r.name == name:
                return r
        names = [r.name for r in self.routes]
        raise MapDescriptionError(f"{self.source}: routes: no route '{name}' (has {names})")

    def named_routes(self) -> list[Route]:
        return self._routes

    @functools.cached_property
    def _routes(self) -> list[Route]:
        out = []
        for spec in self.routes:
            pts: list[Vec2] = []
            half = math.inf
            for name in spec.lanes:
                lane = self.lane(name)
                half = min(half, lane.half_width_m)
                line = [(round(x, 9), round(y, 9)) for x, y, _ in self.centre_line(lane)]
                pts += line[1:] if pts else line
            if spec.loop:
                pts[-1] = pts[0]
            out.append(Route(spec.name, list(spec.lanes), spec.loop, pts, half))
        return out

    def named_spawns(self) -> list[NamedSpawn]:
        out = []
        for s in self.spawns:
            if s.route is not None:
                pose = self.route(s.route).pose_at(s.along_m or 0.0)
            else:
                assert s.position_m is not None and s.yaw_deg is not None
                pose = Pose(s.position_m[0], s.position_m[1], math.radians(s.yaw_deg))
            r6 = Pose(round(pose.x_m, 6), round(pose.y_m, 6), round(pose.yaw_rad, 9))
            out.append(NamedSpawn(s.name, r6, s.route))
        return out

    def road(self, name: str) -> Road:
        for r in self.roads:
            if r.name == name:
                return r
        raise MapDescriptionError(f"{self.source}: roads: no road '{name}'")

    def stop_line_yaw_rad(self, stop: StopLine) -> float:
        """Direction of the painted stop line: across its lane."""
        _, heading = geometry.nearest_on_polyline(stop.centre_m, self.centre_line(stop.lane))
        return heading + math.pi / 2
