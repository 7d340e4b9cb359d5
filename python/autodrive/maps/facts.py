"""The facts of the Parking School map that the parking mission and its sweep use, read from
its one description (maps/parking_school.yaml) through autodrive.maps."""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

from autodrive import maps
from autodrive.core import vehicle
from autodrive.core.geometry import Pose, Rect

PARKING_SCHOOL = "parking_school"


@dataclass(frozen=True)
class ParkingLot:
    spawn: Pose  # the car's default start (rear axle) in the world [m, m, rad]
    slot_goals: tuple[Pose, ...]  # rear-axle pose parked forward-in, per slot [m, m, rad]
    slot_centres: tuple[Pose, ...]  # each slot's centre and yaw [m, m, rad]
    obstacles: tuple[Rect, ...]  # collidable boxes and cones

    @property
    def slots(self) -> int:
        return len(self.slot_goals)


@lru_cache(maxsize=None)
def parking_school() -> ParkingLot:
    """Parking School's spawn, slots and obstacles (the car's figures from vehicle.load())."""
    m = maps.load(PARKING_SCHOOL)
    car = vehicle.load()
    spawn = m.spawn_pose()
    goals = tuple(m.slot_goal(k, car) for k in range(len(m.parking_slots)))
    return ParkingLot(
        spawn=(spawn.x_m, spawn.y_m, spawn.yaw_rad),
        slot_goals=tuple((g.x_m, g.y_m, g.yaw_rad) for g in goals),
        slot_centres=tuple((s.centre_m[0], s.centre_m[1], s.yaw_rad) for s in m.parking_slots),
        obstacles=tuple((r.x_m, r.y_m, r.half_x_m, r.half_y_m, r.yaw_rad) for r in m.obstacles()),
    )
