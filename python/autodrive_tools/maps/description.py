"""MapDescription: one loaded map (its description plus the kit) and the questions tools ask it."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Literal, Union

from . import geometry
from ..geometry import wrap
from .model import Fixture, Kit, Lane, MapDescriptionError, MapFile, ParkingSlot, Pose, Rect
from .model import Road, StopLine

if TYPE_CHECKING:
    from ..vehicle import Vehicle


@dataclass(frozen=True)
class MapDescription(MapFile):
    """A map as described in sim/mujoco_hil/maps/<name>.yaml, with the kit it is built from."""

    name: str
    source: Path
    kit: Kit

    # --- poses and places ---------------------------------------------------------------------

    def spawn_pose(self) -> Pose:
        """Car 1's default start pose (the MJCF 'spawn' site) [m, m, rad]."""
        return self.spawn.pose

    def slot(self, key: Union[str, int]) -> ParkingSlot:
        """A parking slot by name ('s2') or by index in the description (2)."""
        if isinstance(key, int) and not isinstance(key, bool):
            if not 0 <= key < len(self.parking_slots):
                raise MapDescriptionError(
                    f"{self.source}: parking_slots: no slot {key} (the map has "
                    f"{len(self.parking_slots)}: 0..{len(self.parking_slots) - 1})"
                )
            return self.parking_slots[key]
        for s in self.parking_slots:
            if s.name == key:
                return s
        names = [s.name for s in self.parking_slots]
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
        """Collidable props (boxes, cones as their bounding squares) as footprint rectangles;
        walls are not included (see walls)."""
        out = [
            Rect(b.centre_m[0], b.centre_m[1], b.size_m[0] / 2, b.size_m[1] / 2, b.yaw_rad)
            for b in self.boxes
        ]
        r = self.kit.cone.radius_m
        out += [Rect(c.position_m[0], c.position_m[1], r, r, 0.0) for c in self.cones]
        return out

    # --- roads ----------------------------------------------------------------------------------

    def lanes(self) -> list[Lane]:
        return [Lane(l.name, r, l.offset_m, l.direction) for r in self.roads for l in r.lanes]

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

    def road(self, name: str) -> Road:
        for r in self.roads:
            if r.name == name:
                return r
        raise MapDescriptionError(f"{self.source}: roads: no road '{name}'")

    def stop_line_yaw_rad(self, stop: StopLine) -> float:
        """Direction of the painted stop line: across its lane."""
        _, heading = geometry.nearest_on_polyline(stop.centre_m, self.centre_line(stop.lane))
        return heading + math.pi / 2

    def all_fixtures(self) -> list[Fixture]:
        return list(self.traffic_lights) + list(self.signs)
