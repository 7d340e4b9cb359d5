"""Gymnasium environments of one car on the simulator library: lane keeping on a named route
and parking to a slot. The car is the HIL car: paper tyres, 1 ms physics, its emulated Nano
(commands reach the wheels through the firmware's slew and steering-rate limits)."""

from __future__ import annotations

import math
from typing import Any, SupportsFloat

import gymnasium as gym
import numpy as np
import numpy.typing as npt

from autodrive.maps import facts as mapfacts
from autodrive.gym import tasks
from autodrive.gym.world import SimError, World
from autodrive.core.geometry import wrap

CONTROL_HZ = 20
LIDAR_MAX_M = 12.0  # observation scale of a LIDAR range (the RPLIDAR A1's range) [m]
START_TRIES = 20  # random start poses drawn until one is clear of obstacles
ROUTE_END_M = 0.1  # an open route is done this close to its end [m]

ObsArray = npt.NDArray[np.float32]


def _period_ms(control_hz: float) -> int:
    period = round(1000.0 / control_hz)
    if period < 1:
        raise ValueError(f"control_hz {control_hz}: the period must be >= 1 ms")
    return period


class _CarEnv(gym.Env[ObsArray, ObsArray]):
    """Shared parts: the world, the action (throttle, steering in [-1, 1]), the LIDAR part."""

    metadata: dict[str, Any] = {"render_modes": ["rgb_array"], "render_fps": CONTROL_HZ}

    def __init__(
        self,
        map_name: str,
        base_obs: int,
        control_hz: float,
        lidar_rays: int,
        max_steps: int,
        render_mode: str | None,
    ) -> None:
        if render_mode not in (None, "rgb_array"):
            raise ValueError(f"render_mode '{render_mode}': only rgb_array")
        self.render_mode = render_mode
        self.period_ms = _period_ms(control_hz)
        self.max_steps = max_steps
        self.lidar_rays = lidar_rays
        camera = (160, 120) if render_mode == "rgb_array" else (0, 0)
        self.world = World(map_name, cars=1, seed=0, lidar_rays=lidar_rays, camera_px=camera)
        n = base_obs + lidar_rays
        self.observation_space = gym.spaces.Box(-np.inf, np.inf, (n,), np.float32)
        self.action_space = gym.spaces.Box(-1.0, 1.0, (2,), np.float32)
        self.steps = 0

    def _lidar_part(self) -> list[float]:
        if self.lidar_rays == 0:
            return []
        r = np.minimum(self.world.lidar(0), LIDAR_MAX_M) / LIDAR_MAX_M
        return [float(v) for v in r]

    def _reset_world(self, poses: list[tasks.Pose]) -> None:
        """Resets with a seed drawn from the env's generator at the first clear pose."""
        for pose in poses:
            try:
                self.world.reset(int(self.np_random.integers(2**31)), [pose])
                break
            except SimError:
                continue
        else:
            raise SimError(f"no clear start pose among {len(poses)} draws")
        self.world.command(0, 0.0, 0.0)
        self.steps = 0

    def _act(self, action: ObsArray) -> None:
        a = np.clip(np.asarray(action, dtype=np.float64), -1.0, 1.0)
        self.world.command(0, float(a[0]), float(a[1]))
        self.world.step(self.period_ms)
        self.steps += 1

    def render(self) -> Any:
        if self.render_mode == "rgb_array":
            return self.world.camera(0)
        return None

    def close(self) -> None:
        self.world.close()


class LaneKeepingEnv(_CarEnv):
    """Keep the lane of a named route. Observation: lateral offset over the half width,
    heading error [rad], forward and lateral speed [m/s], yaw rate [rad/s], steering angle
    [rad], the Nano's engaged flag, then optional LIDAR ranges over 12 m. Reward: metres of
    progress along the route minus 0.05 per step times the squared offset ratio. Ends when
    the car leaves the lane, collides or reaches the end of an open route (e.g. Intersection
    School's "north_to_east"); truncated after max_steps."""

    BASE_OBS = 7

    def __init__(
        self,
        map_name: str = "driving_school",
        route: str = "loop_ccw",
        control_hz: float = CONTROL_HZ,
        lidar_rays: int = 0,
        max_steps: int = 400,
        render_mode: str | None = None,
    ) -> None:
        super().__init__(map_name, self.BASE_OBS, control_hz, lidar_rays, max_steps, render_mode)
        self.route = tasks.route(map_name, route)
        try:
            self.world.set_route(0, route)  # the MJCF numeric of the maps contract
        except SimError:
            self.world.set_route_points(
                0, self.route.points_m, self.route.half_width_m, self.route.loop
            )
        self.progress_m = 0.0

    def _obs(self) -> tuple[ObsArray, Any]:
        o = self.world.observe_raw(0)
        hw = o.route_half_width_m
        base = [
            o.route_lateral_m / hw,
            o.route_heading_err_rad,
            o.vel_body_m_s[0],
            o.vel_body_m_s[1],
            o.gyro_body_rad_s[2],
            o.steering_rad,
            float(o.nano_engaged),
        ]
        return np.asarray(base + self._lidar_part(), dtype=np.float32), o

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[ObsArray, dict[str, Any]]:
        super().reset(seed=seed)
        n = len(self.route.points_m)
        last = n if self.route.loop else max(1, n - 40)  # an open route: not at its very end
        poses = [
            self.route.pose_at(
                int(self.np_random.integers(last)),
                float(self.np_random.uniform(-0.03, 0.03)),
                float(self.np_random.uniform(-0.1, 0.1)),
            )
            for _ in range(START_TRIES)
        ]
        self._reset_world(poses)
        obs, o = self._obs()
        self.progress_m = float(o.route_progress_m)
        return obs, {"time_s": float(o.time_s)}

    def step(self, action: ObsArray) -> tuple[ObsArray, SupportsFloat, bool, bool, dict[str, Any]]:
        self._act(action)
        obs, o = self._obs()
        ds = float(o.route_progress_m) - self.progress_m
        if self.route.loop:  # across the loop's seam
            ds = math.remainder(ds, float(o.route_length_m))
        self.progress_m = float(o.route_progress_m)
        reward = ds - 0.05 * float(obs[0]) ** 2
        arrived = not self.route.loop and self.progress_m > float(o.route_length_m) - ROUTE_END_M
        terminated = bool(o.off_lane or o.in_collision or arrived)
        truncated = self.steps >= self.max_steps
        info = {
            "off_lane": bool(o.off_lane),
            "in_collision": bool(o.in_collision),
            "arrived": arrived,
        }
        return obs, reward, terminated, truncated, info


class ParkingEnv(_CarEnv):
    """Park in a free slot of Parking School (default 2, the demo's), forward in. Observation: the goal pose in the car's
    frame (x, y [m], cos and sin of the yaw difference), forward and lateral speed [m/s], yaw
    rate [rad/s], steering angle [rad], then optional LIDAR ranges over 12 m. Reward: the
    decrease of the pose error (distance [m] + 0.2 m/rad * |yaw error|); +10 and done when
    within 5 cm and 0.1 rad at under 5 cm/s; -10 and done on a collision."""

    BASE_OBS = 8
    DONE_M, DONE_RAD, DONE_M_S = 0.05, 0.1, 0.05
    YAW_WEIGHT_M = 0.2

    def __init__(
        self,
        slot: int = 2,
        control_hz: float = CONTROL_HZ,
        lidar_rays: int = 0,
        max_steps: int = 600,
        render_mode: str | None = None,
    ) -> None:
        super().__init__(
            mapfacts.PARKING_SCHOOL, self.BASE_OBS, control_hz, lidar_rays, max_steps, render_mode
        )
        lot = mapfacts.parking_school()
        if not 0 <= slot < lot.slots:
            raise ValueError(f"slot {slot}: Parking School has slots 0..{lot.slots - 1}")
        side = tasks.sidecar(mapfacts.PARKING_SCHOOL)
        taken = {p["slot"] for p in side.get("parked", [])}
        name = side["parking_slots"][slot]["name"]
        if name in taken:
            free = [k for k, sl in enumerate(side["parking_slots"]) if sl["name"] not in taken]
            raise ValueError(f"slot {slot} ('{name}') holds a parked car; free slots: {free}")
        self.goal = lot.slot_goals[slot]
        self.spawn = lot.spawn
        self.error = 0.0

    def _goal_in_car(self, o: Any) -> tuple[float, float, float]:
        dx, dy = self.goal[0] - o.pos_m[0], self.goal[1] - o.pos_m[1]
        c, s = math.cos(o.yaw_rad), math.sin(o.yaw_rad)
        return c * dx + s * dy, -s * dx + c * dy, wrap(self.goal[2] - o.yaw_rad)

    def _obs(self) -> tuple[ObsArray, Any, float]:
        o = self.world.observe_raw(0)
        gx, gy, gyaw = self._goal_in_car(o)
        base = [gx, gy, math.cos(gyaw), math.sin(gyaw)]
        base += [o.vel_body_m_s[0], o.vel_body_m_s[1], o.gyro_body_rad_s[2], o.steering_rad]
        error = math.hypot(gx, gy) + self.YAW_WEIGHT_M * abs(gyaw)
        return np.asarray(base + self._lidar_part(), dtype=np.float32), o, error

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[ObsArray, dict[str, Any]]:
        super().reset(seed=seed)
        x, y, yaw = self.spawn
        poses = [
            (
                x + float(self.np_random.uniform(-0.1, 0.1)),
                y + float(self.np_random.uniform(-0.05, 0.05)),
                yaw + float(self.np_random.uniform(-0.15, 0.15)),
            )
            for _ in range(START_TRIES)
        ]
        self._reset_world(poses)
        obs, o, self.error = self._obs()
        return obs, {"time_s": float(o.time_s)}

    def step(self, action: ObsArray) -> tuple[ObsArray, SupportsFloat, bool, bool, dict[str, Any]]:
        self._act(action)
        obs, o, error = self._obs()
        reward = self.error - error
        self.error = error
        gx, gy, gyaw = self._goal_in_car(o)
        parked = (
            math.hypot(gx, gy) < self.DONE_M
            and abs(gyaw) < self.DONE_RAD
            and abs(o.vel_body_m_s[0]) < self.DONE_M_S
        )
        if parked:
            reward += 10.0
        if o.in_collision:
            reward -= 10.0
        terminated = bool(parked or o.in_collision)
        truncated = self.steps >= self.max_steps
        return (
            obs,
            reward,
            terminated,
            truncated,
            {"parked": parked, "in_collision": bool(o.in_collision)},
        )
