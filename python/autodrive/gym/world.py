"""Worlds of the simulator in process (the learning API): N cars on a map, each with its
emulated Nano; reset with a seed, command, step by a control period, observe."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from autodrive.gym import _lib

ERR_BYTES = 2048
F64 = npt.NDArray[np.float64]


class SimError(RuntimeError):
    """A refusal or failure of the simulator library, with its message."""


@dataclass(frozen=True)
class Observation:
    """One car's observation (the C struct ad_obs_t; car axes x forward, y left, z up)."""

    time_s: float
    pos_m: F64  # base_link (rear-axle centre) in the world
    quat_wxyz: F64
    yaw_rad: float
    vel_body_m_s: F64
    gyro_body_rad_s: F64
    steering_rad: float
    wheel_speed_rad_s: F64  # fl fr rl rr
    imu_accel_m_s2: F64
    imu_gyro_rad_s: F64
    in_collision: bool
    off_lane: bool
    has_route: bool
    route_lateral_m: float  # + left of the centre line
    route_heading_err_rad: float
    route_progress_m: float
    route_length_m: float
    route_half_width_m: float
    nano_engaged: bool


class World:
    """One world (see sim/mujoco_hil/include/autodrive_sim_api.h). Cars are 0-based."""

    def __init__(
        self,
        map_name: str,
        cars: int = 1,
        seed: int = 0,
        lidar_rays: int = 0,
        camera_px: tuple[int, int] = (0, 0),
        tyre_model: int = -1,
    ) -> None:
        self._ffi, self._lib = _lib.load()
        ffi = self._ffi
        self._err = ffi.new("char[]", ERR_BYTES)
        self._map = ffi.new("char[]", map_name.encode())
        cfg = ffi.new("ad_world_config_t *")
        cfg.map = self._map
        cfg.cars = cars
        cfg.seed = seed
        cfg.lidar_rays = lidar_rays
        cfg.camera_width_px, cfg.camera_height_px = camera_px
        cfg.tyre_model = tyre_model
        w = self._lib.ad_world_create(cfg, self._err, ERR_BYTES)
        if w == ffi.NULL:
            raise SimError(f"world on map '{map_name}': {self._message()}")
        self._w = ffi.gc(w, self._lib.ad_world_destroy)
        self.map_name = map_name
        self.cars = cars
        self.lidar_rays = lidar_rays
        self.camera_px = camera_px
        self._obs = ffi.new("ad_obs_t *")
        self._lidar = np.zeros(max(lidar_rays, 1), dtype=np.float32)
        self._camera = np.zeros((camera_px[1], camera_px[0], 3), dtype=np.uint8)

    @property
    def handle(self) -> object:
        """The C world (ad_world_t *) for step_worlds."""
        return self._w

    def _message(self) -> str:
        return str(self._ffi.string(self._err).decode(errors="replace"))

    def _check(self, rc: int, what: str) -> None:
        if rc != 0:
            raise SimError(f"{what}: {self._message()}")

    def close(self) -> None:
        """Frees the world now (else when garbage-collected)."""
        if self._w is not None:
            self._ffi.release(self._w)
            self._w = None

    @property
    def time_s(self) -> float:
        return float(self._lib.ad_world_time_s(self._w))

    def reset(self, seed: int, poses: Sequence[tuple[float, float, float]] | None = None) -> None:
        """Sim time 0 with seed; poses (x [m], y [m], yaw [rad] per car) become the start poses."""
        p = self._ffi.NULL
        if poses is not None:
            if len(poses) != self.cars:
                raise SimError(f"reset: {len(poses)} poses for {self.cars} cars")
            p = self._ffi.new("double[]", [float(v) for pose in poses for v in pose])
        self._check(self._lib.ad_world_reset(self._w, seed, p, self._err, ERR_BYTES), "reset")

    def command(self, car: int, throttle: float, steering: float) -> None:
        """What car's driver sends in its next COMMAND frames (normalised, [-1, 1])."""
        rc = self._lib.ad_world_command(
            self._w, car, float(throttle), float(steering), self._err, ERR_BYTES
        )
        self._check(rc, "command")

    def step(self, period_ms: int) -> None:
        """Advances the world by period_ms physics steps of 1 ms."""
        self._check(self._lib.ad_world_step(self._w, period_ms, self._err, ERR_BYTES), "step")

    def observe_raw(self, car: int) -> Any:
        """car's observation as the C struct (ad_obs_t *, overwritten by the next call)."""
        if self._lib.ad_world_observe(self._w, car, self._obs) != 0:
            raise SimError(f"observe: car {car}: the world has cars 0..{self.cars - 1}")
        return self._obs

    def observe(self, car: int) -> Observation:
        self.observe_raw(car)
        b = self._ffi.buffer

        def vec(field: object) -> F64:
            return np.frombuffer(b(field), dtype=np.float64).copy()

        c = self._obs
        return Observation(
            time_s=float(c.time_s),
            pos_m=vec(c.pos_m),
            quat_wxyz=vec(c.quat_wxyz),
            yaw_rad=float(c.yaw_rad),
            vel_body_m_s=vec(c.vel_body_m_s),
            gyro_body_rad_s=vec(c.gyro_body_rad_s),
            steering_rad=float(c.steering_rad),
            wheel_speed_rad_s=vec(c.wheel_speed_rad_s),
            imu_accel_m_s2=vec(c.imu_accel_m_s2),
            imu_gyro_rad_s=vec(c.imu_gyro_rad_s),
            in_collision=bool(c.in_collision),
            off_lane=bool(c.off_lane),
            has_route=bool(c.has_route),
            route_lateral_m=float(c.route_lateral_m),
            route_heading_err_rad=float(c.route_heading_err_rad),
            route_progress_m=float(c.route_progress_m),
            route_length_m=float(c.route_length_m),
            route_half_width_m=float(c.route_half_width_m),
            nano_engaged=bool(c.nano_engaged),
        )

    def lidar(self, car: int) -> npt.NDArray[np.float32]:
        """car's LIDAR scan cast now: lidar_rays ranges [m], CCW from the car's x; inf: none."""
        buf = self._ffi.from_buffer("float[]", self._lidar)
        rc = self._lib.ad_world_lidar(self._w, car, buf, self.lidar_rays, self._err, ERR_BYTES)
        self._check(rc, "lidar")
        return self._lidar.copy()

    def camera(self, car: int) -> npt.NDArray[np.uint8]:
        """car's front camera rendered now: height x width x 3 RGB."""
        buf = self._ffi.from_buffer("uint8_t[]", self._camera)
        rc = self._lib.ad_world_camera(self._w, car, buf, self._camera.nbytes, self._err, ERR_BYTES)
        self._check(rc, "camera")
        return self._camera.copy()

    def set_route(self, car: int, name: str | None) -> None:
        """car follows the map's route (MJCF numeric route_<name> / lane_<name>); None: none."""
        n = self._ffi.new("char[]", name.encode()) if name is not None else self._ffi.NULL
        rc = self._lib.ad_world_set_route(self._w, car, n, self._err, ERR_BYTES)
        self._check(rc, "route")

    def set_route_points(
        self, car: int, xy: npt.ArrayLike, half_width_m: float, loop: bool
    ) -> None:
        """car follows a polyline of (x, y) [m] in driving order."""
        pts = np.ascontiguousarray(np.asarray(xy, dtype=np.float64).reshape(-1, 2))
        buf = self._ffi.from_buffer("double[]", pts)
        rc = self._lib.ad_world_set_route_points(
            self._w, car, buf, len(pts), half_width_m, int(loop), self._err, ERR_BYTES
        )
        self._check(rc, "route points")

    def bare_mj_step_s(self, steps: int) -> float:
        """Wall time [s] of a bare mj_step loop on a copy of this world (MuJoCo alone)."""
        return float(self._lib.ad_world_bare_mj_step_s(self._w, steps))


def step_worlds(worlds: Sequence[World], period_ms: int, threads: int = 1) -> None:
    """Steps every world by period_ms in one call (the batch API), on up to threads threads
    (worlds are independent: the same result as one by one)."""
    if not worlds:
        return
    ffi, lib = _lib.load()
    arr = ffi.new("ad_world_t *[]", [w.handle for w in worlds])
    err = ffi.new("char[]", ERR_BYTES)
    if lib.ad_worlds_step_threads(arr, len(worlds), period_ms, threads, err, ERR_BYTES) != 0:
        raise SimError(f"batch step: {ffi.string(err).decode(errors='replace')}")
