"""cffi binding (ABI mode) of autodrive_path_tracking, the one pure pursuit that the simulator's
route driver, the autonomy and the city driver use too. The declarations come from the one header,
common/path_tracking/include/autodrive/pure_pursuit.h, between its CFFI markers."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Any

import cffi

from autodrive.core.geometry import Point, Pose
from autodrive.core.settings import settings
from autodrive.gym._lib import declarations, find_library

HEADER = settings().path_tracking_header
LIB_NAME = "libautodrive_path_tracking.so"


def library_path() -> Path:
    """The path tracking library (see learn._lib.find_library)."""
    return find_library(LIB_NAME, "autodrive_path_tracking_shared")


@lru_cache(maxsize=1)
def load() -> tuple[Any, Any]:
    """(ffi, lib) of the library."""
    ffi = cffi.FFI()
    ffi.cdef(declarations(HEADER))
    return ffi, ffi.dlopen(str(library_path()))


@dataclass(frozen=True)
class Vehicle:
    """The steering geometry: wheelbase [m], steering limit [rad]."""

    wheelbase_m: float
    steer_limit_rad: float


def default_vehicle() -> Vehicle:
    """Nigel's, from the generated vehicle header (vehicle/nigel.params)."""
    _, lib = load()
    v = lib.pp_vehicle_default()
    return Vehicle(float(v.wheelbase_m), float(v.steer_limit_rad))


def _c_vehicle(v: Vehicle) -> Any:
    ffi, _ = load()
    return ffi.new(
        "pp_vehicle_t *", {"wheelbase_m": v.wheelbase_m, "steer_limit_rad": v.steer_limit_rad}
    )


def steer_to(pose: Pose, goal: Point, vehicle: Vehicle | None = None) -> float:
    """Pure pursuit's steering angle [rad, + left] from the rear axle at pose towards goal,
    clamped to the vehicle's limit."""
    _, lib = load()
    v = _c_vehicle(vehicle or default_vehicle())
    return float(lib.pp_steer_to(pose[0], pose[1], pose[2], goal[0], goal[1], v))


class Polyline:
    """A sampled path for the goal-by-distance rule: the goal is the first sample, from a
    progress index on, at least the lookahead from the car."""

    def __init__(self, points: Sequence[Point]) -> None:
        ffi, _ = load()
        self.n = len(points)
        self._xy = ffi.new("double[]", [c for p in points for c in p])

    def goal_index(self, start: int, x_m: float, y_m: float, lookahead_m: float) -> int:
        """The first index in [start, n) at least lookahead_m [m] from (x, y); n if none is."""
        _, lib = load()
        return int(lib.pp_goal_index(self._xy, self.n, start, x_m, y_m, lookahead_m))


class PathTracker:
    """A polyline followed by arc length: the goal lies the lookahead along it past the car's
    projection (the simulator's route driver's rule)."""

    def __init__(self, points: Sequence[Point], loop: bool, vehicle: Vehicle | None = None) -> None:
        ffi, lib = load()
        self._xy = ffi.new("double[]", [c for p in points for c in p])
        self._path = ffi.new("pp_path_t *")
        self._state = ffi.new("pp_state_t *")
        self._vehicle = _c_vehicle(vehicle or default_vehicle())
        err = ffi.new("char[]", 256)
        if lib.pp_path_init(self._path, self._xy, len(points), int(loop), err, 256) != 0:
            raise ValueError(ffi.string(err).decode())
        self._path = ffi.gc(self._path, lib.pp_path_free)

    @property
    def length_m(self) -> float:
        """Its length [m] (a loop's closing segment included)."""
        return float(self._path.length_m)

    def steer_nearest(self, pose: Pose, lookahead_m: float) -> float:
        """Steering angle [rad, + left] at pose towards the point lookahead_m [m] past the path
        point nearest to it (whole-path search: no progress kept)."""
        _, lib = load()
        lib.pp_reset(self._state, self._path, pose[0], pose[1])
        return float(
            lib.pp_steer(
                self._state, self._path, pose[0], pose[1], pose[2], lookahead_m, self._vehicle
            )
        )
