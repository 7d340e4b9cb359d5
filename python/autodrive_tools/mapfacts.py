"""The facts of the Parking School map the Python tools use (spawn pose, slots, obstacles),
read in ONE function, `parking_school()`, so that switching to the map-description API is a
change in one place."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from functools import lru_cache

from .geometry import Pose, Rect
from .paths import PARKING_SCHOOL_MJCF

CONE_HALF_SIZE_M = 0.025  # a cone's footprint as a square, for clearances


@dataclass(frozen=True)
class ParkingLot:
    spawn: Pose  # the car's default start (rear axle) in the world [m, m, rad]
    slot_x0_m: float  # centre of slot 0
    slot_pitch_m: float  # from one slot centre to the next along x
    slot_y_m: float  # centre line of the slots
    slot_yaw_rad: float  # heading of a car parked forward-in
    slots: int
    obstacles: tuple[Rect, ...]  # collidable boxes and cones


@lru_cache(maxsize=None)
def parking_school() -> ParkingLot:
    """Reads the map (today: its MJCF; the slot layout as sim/mujoco_hil/tools/gen_maps.py lays
    it out: 0.3 m wide slots between lines at x = -1.2 + 0.3 k, centre line y = 1.25 m)."""
    path = PARKING_SCHOOL_MJCF
    try:
        text = path.read_text()
    except OSError as err:
        raise RuntimeError(f"{path}: cannot read the map ({err})") from err
    m = re.search(
        r'<site name="spawn" pos="([-\d.]+) ([-\d.]+) [-\d.]+" euler="[-\d.]+ [-\d.]+ ([-\d.]+)"',
        text,
    )
    if not m:
        raise RuntimeError(f'{path}: no <site name="spawn" pos=.. euler=..>')
    spawn = (float(m.group(1)), float(m.group(2)), math.radians(float(m.group(3))))
    obstacles: list[Rect] = []
    for m in re.finditer(
        r'<geom name="box_\w+" type="box" pos="([-\d. ]+)" size="([-\d. ]+)" '
        r'euler="[-\d.]+ [-\d.]+ ([-\d.]+)"',
        text,
    ):
        p = [float(v) for v in m.group(1).split()]
        s = [float(v) for v in m.group(2).split()]
        obstacles.append((p[0], p[1], s[0], s[1], float(m.group(3))))
    for m in re.finditer(r'<body name="cone_\d+" pos="([-\d. ]+)"', text):
        p = [float(v) for v in m.group(1).split()]
        obstacles.append((p[0], p[1], CONE_HALF_SIZE_M, CONE_HALF_SIZE_M, 0.0))
    return ParkingLot(
        spawn=spawn,
        slot_x0_m=-1.05,
        slot_pitch_m=0.30,
        slot_y_m=1.25,
        slot_yaw_rad=math.pi / 2,
        slots=6,
        obstacles=tuple(obstacles),
    )
