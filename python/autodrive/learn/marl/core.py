"""cffi binding (ABI mode) of autodrive_marl_core, the observation builder and time-to-collision
shield that the C++ autodrive-marl uses too. The declarations come from the one header,
common/marl_core/include/autodrive/marl_core.h, between its CFFI markers."""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Any

import cffi
import numpy as np
import numpy.typing as npt

from autodrive.core import vehicle
from autodrive.gym._lib import declarations, find_library
from autodrive.core.settings import settings

HEADER = settings().marl_core_header
LIB_NAME = "libautodrive_marl_core.so"
ERR_BYTES = 512


class CoreError(RuntimeError):
    """A refusal of the C core, with its message."""


def library_path() -> Path:
    """The MARL core library (see learn._lib.find_library)."""
    return find_library(LIB_NAME, "autodrive_marl_core_shared")


@lru_cache(maxsize=1)
def load() -> tuple[Any, Any]:
    """(ffi, lib) of the core."""
    ffi = cffi.FFI()
    # cffi's ABI mode takes integer #defines only: the float scales stay C-side
    text = re.sub(r"^#define \w+ [0-9]*\.[0-9]+\b.*$", "", declarations(HEADER), flags=re.M)
    ffi.cdef(text)
    return ffi, ffi.dlopen(str(library_path()))


def _constant(name: str) -> float:
    ffi, lib = load()
    return float(getattr(lib, name))


OBS_VERSION = 1
OBS_DIM = 24  # checked against the header's ADM_OBS_DIM by check_layout()


@dataclass(frozen=True)
class Car:
    """A car for the core: vehicle id, base_link x, y [m], yaw [rad], speed along it [m/s]."""

    id: int
    x_m: float
    y_m: float
    yaw_rad: float
    speed_m_s: float


@dataclass(frozen=True)
class ShieldResult:
    throttle: float
    steering: float
    intervened: bool
    peer_id: int
    ttc_s: float
    steered: bool  # the lane term replaced the steering


@dataclass(frozen=True)
class Lane:
    """A car's own lane for the shield's lane term: its route as route_buffer() made it, the
    nearest route point found last (route_waypoint's hint), the lane's half width [m] and the
    wheels' steering now (normalised: the measured angle where known, else the last command)."""

    route: tuple[Any, int]
    hint: int
    half_width_m: float
    steering_now: float


def check_layout() -> None:
    """The Python constants agree with the header (the one place of the layout)."""
    ffi, lib = load()
    if lib.ADM_OBS_DIM != OBS_DIM or lib.ADM_OBS_VERSION != OBS_VERSION:
        raise CoreError(
            f"{HEADER}: layout v{lib.ADM_OBS_VERSION} D={lib.ADM_OBS_DIM}, Python expects "
            f"v{OBS_VERSION} D={OBS_DIM}"
        )


class Core:
    """The core with its buffers and the shield configured for the car of
    vehicle/nigel.params (top speed: the motor's no-load speed times the wheel radius)."""

    def __init__(self) -> None:
        self.ffi, self.lib = load()
        check_layout()
        ffi = self.ffi
        self._err = ffi.new("char[]", ERR_BYTES)
        self._obs = np.zeros(OBS_DIM, dtype=np.float32)
        self._obs_c = ffi.from_buffer("float[]", self._obs)
        self._self = ffi.new("adm_car_t *")
        self._peers = ffi.new("adm_car_t[]", 32)
        self._goal = ffi.new("double[2]")
        self._wp = ffi.new("double[2]")
        self._cmd = ffi.new("adm_command_t *")
        self._res = ffi.new("adm_shield_result_t *")
        self._lane = ffi.new("adm_lane_t *")
        self._hint = ffi.new("int *")
        self._remaining = ffi.new("double *")
        self.shield_config = ffi.new("adm_shield_config_t *")
        self.lib.adm_shield_defaults(self.shield_config)
        v = vehicle.load()
        size, offset = v.vector("chassis_size_m"), v.vector("chassis_offset_m")
        c = self.shield_config
        c.chassis_length_m, c.chassis_width_m, c.chassis_offset_m = size[0], size[1], offset[0]
        c.wheelbase_m = v.number("wheelbase_m")
        c.steer_limit_rad = v.number("steer_limit_rad")
        c.top_speed_m_s = top_speed_m_s()
        c.steer_rate_rad_s = v.number("steer_rate_rad_s")

    def _message(self) -> str:
        return str(self.ffi.string(self._err).decode(errors="replace"))

    @staticmethod
    def _fill(dst: Any, car: Car) -> None:
        dst.id, dst.x_m, dst.y_m = car.id, car.x_m, car.y_m
        dst.yaw_rad, dst.speed_m_s = car.yaw_rad, car.speed_m_s

    def _fill_peers(self, peers: Sequence[Car]) -> int:
        if len(peers) > len(self._peers):
            raise CoreError(f"{len(peers)} peers, at most {len(self._peers)}")
        for i, p in enumerate(peers):
            self._fill(self._peers[i], p)
        return len(peers)

    def observation(
        self,
        me: Car,
        goal_xy_m: tuple[float, float],
        waypoint_xy_m: tuple[float, float],
        last_steering: float,
        peers: Sequence[Car],
    ) -> npt.NDArray[np.float32]:
        """The layout-v1 observation (a copy) of me among peers (me may be among them)."""
        self._fill(self._self, me)
        self._goal[0], self._goal[1] = goal_xy_m
        self._wp[0], self._wp[1] = waypoint_xy_m
        n = self._fill_peers(peers)
        rc = self.lib.adm_observation(
            self._self,
            self._goal,
            self._wp,
            float(last_steering),
            self._peers,
            n,
            self._obs_c,
            OBS_DIM,
            self._err,
            ERR_BYTES,
        )
        if rc != 0:
            raise CoreError(self._message())
        return self._obs.copy()

    def route_waypoint(
        self, route_xy_m: Any, x_m: float, y_m: float, lookahead_m: float, hint: int
    ) -> tuple[tuple[float, float], float, int]:
        """(waypoint, remaining length [m], new hint) on a route given as a C double[] of
        n x 2 (see route_buffer)."""
        buf, n = route_xy_m
        self._hint[0] = hint
        rc = self.lib.adm_route_waypoint(
            buf,
            n,
            x_m,
            y_m,
            lookahead_m,
            self._hint,
            self._wp,
            self._remaining,
            self._err,
            ERR_BYTES,
        )
        if rc != 0:
            raise CoreError(self._message())
        return (
            (float(self._wp[0]), float(self._wp[1])),
            float(self._remaining[0]),
            int(self._hint[0]),
        )

    def route_buffer(self, xy: npt.ArrayLike) -> tuple[Any, int]:
        """A route's points as the C array route_waypoint takes."""
        pts = np.ascontiguousarray(np.asarray(xy, dtype=np.float64).reshape(-1, 2))
        return self.ffi.new("double[]", pts.ravel().tolist()), len(pts)

    def shield(
        self,
        me: Car,
        throttle: float,
        steering: float,
        peers: Sequence[Car],
        lane: Lane | None = None,
    ) -> ShieldResult:
        """The command to send instead of (throttle, steering), and whether the shield braked
        (or, with lane, steered back into the lane)."""
        self._fill(self._self, me)
        self._cmd.throttle, self._cmd.steering = float(throttle), float(steering)
        n = self._fill_peers(peers)
        lane_c = self.ffi.NULL
        if lane is not None:
            lc = self._lane
            lc.route_xy_m, lc.n_points = lane.route
            lc.hint_index, lc.half_width_m = lane.hint, lane.half_width_m
            lc.steering_now = lane.steering_now
            lane_c = lc
        rc = self.lib.adm_shield(
            self.shield_config,
            self._self,
            self._cmd,
            self._peers,
            n,
            lane_c,
            self._res,
            self._err,
            ERR_BYTES,
        )
        if rc != 0:
            raise CoreError(self._message())
        r = self._res
        return ShieldResult(
            float(r.command.throttle),
            float(r.command.steering),
            bool(r.intervened),
            int(r.peer_id),
            float(r.ttc_s),
            bool(r.steered),
        )


def top_speed_m_s() -> float:
    """The car's speed at full throttle [m/s]: motor no-load speed x wheel radius."""
    v = vehicle.load()
    return v.number("motor_noload_speed_rad_s") * v.number("wheel_radius_m")
