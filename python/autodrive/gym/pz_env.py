"""A PettingZoo parallel environment of N cars in one world: the intersection (Intersection
School; Parking School until that map exists). Every car is the HIL car with its emulated
Nano. Seeds make every episode repeatable: reset(seed) draws the world's seed and the start
offsets from one generator."""

from __future__ import annotations

import functools
import math
from typing import Any

import gymnasium as gym
import numpy as np
import numpy.typing as npt
from pettingzoo import ParallelEnv

from autodrive.core import channels
from autodrive.gym import tasks
from autodrive.gym.world import World

CONTROL_HZ = 20
NEIGHBOUR_SCALE_M = 2.0  # other cars' relative positions are observed over this [m]
ROUTE_END_M = 0.1  # an open route is done this close to its end [m]

ObsArray = npt.NDArray[np.float32]
# ParallelEnv.step's result: observations, rewards, terminations, truncations, infos per agent
StepResult = tuple[
    dict[str, ObsArray],
    dict[str, float],
    dict[str, bool],
    dict[str, bool],
    dict[str, dict[str, Any]],
]


class IntersectionEnv(ParallelEnv[str, ObsArray, ObsArray]):  # type: ignore[misc]
    """N cars (agents "nigel1".."nigelN"). With the map's routes (Intersection School), car i
    drives routes[i * len(routes) // N] from its start; observation: offset over the half
    width, heading error [rad], progress fraction, forward and lateral speed [m/s], yaw rate
    [rad/s], steering [rad], then each other car's position in this car's frame over 2 m.
    Without routes (Parking School) the first three are x, y [m] and yaw [rad] and the reward
    is forward distance. Reward: metres of progress per step, -10 on a collision. An agent is
    done on a collision, off its lane, or at the end of its route."""

    metadata: dict[str, Any] = {"name": "autodrive_intersection_v0", "render_modes": []}

    def __init__(
        self,
        cars: int = 4,
        map_name: str | None = None,
        control_hz: float = CONTROL_HZ,
        max_steps: int = 400,
        render_mode: str | None = None,
    ) -> None:
        self.map_name = map_name or tasks.multi_car_map()
        self.render_mode = render_mode
        self.period_ms = max(1, round(1000.0 / control_hz))
        self.max_steps = max_steps
        self.world = World(self.map_name, cars=cars, seed=0)
        self.possible_agents = [channels.vehicle_name(i + 1).lower() for i in range(cars)]
        self.agents: list[str] = []
        names = tasks.routes(self.map_name)
        self.routes = [names[i * len(names) // cars] for i in range(cars)] if names else []
        self.starts: list[tasks.Pose] = []
        for car, r in enumerate(self.routes):
            self.world.set_route(car, r)
            start = tasks.route_start(self.map_name, r)
            self.starts.append(start if start else tasks.route(self.map_name, r).pose_at(0))
        self.n_obs = 7 + 2 * (cars - 1)
        self.progress = np.zeros(cars)
        self.steps = 0
        self.rng = np.random.default_rng()

    @functools.lru_cache(maxsize=None)
    def observation_space(self, agent: str) -> gym.spaces.Space[Any]:
        return gym.spaces.Box(-np.inf, np.inf, (self.n_obs,), np.float32)

    @functools.lru_cache(maxsize=None)
    def action_space(self, agent: str) -> gym.spaces.Space[Any]:
        return gym.spaces.Box(-1.0, 1.0, (2,), np.float32)

    def _car(self, agent: str) -> int:
        return self.possible_agents.index(agent)

    def _obs(self, car: int, poses: list[tuple[float, float, float]]) -> ObsArray:
        o = self.world.observe_raw(car)
        if self.routes:
            head = [
                o.route_lateral_m / o.route_half_width_m,
                o.route_heading_err_rad,
                o.route_progress_m / o.route_length_m,
            ]
        else:
            head = [o.pos_m[0], o.pos_m[1], o.yaw_rad]
        v = [o.vel_body_m_s[0], o.vel_body_m_s[1], o.gyro_body_rad_s[2], o.steering_rad]
        x, y, yaw = poses[car]
        c, s = math.cos(yaw), math.sin(yaw)
        rel: list[float] = []
        for other, (ox, oy, _) in enumerate(poses):
            if other != car:
                dx, dy = ox - x, oy - y
                rel += [
                    (c * dx + s * dy) / NEIGHBOUR_SCALE_M,
                    (-s * dx + c * dy) / NEIGHBOUR_SCALE_M,
                ]
        return np.asarray(head + v + rel, dtype=np.float32)

    def _poses(self) -> list[tuple[float, float, float]]:
        out = []
        for car in range(self.world.cars):
            o = self.world.observe_raw(car)
            out.append((float(o.pos_m[0]), float(o.pos_m[1]), float(o.yaw_rad)))
        return out

    def reset(
        self, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, ObsArray], dict[str, dict[str, Any]]]:
        if seed is not None:
            self.rng = np.random.default_rng(seed)
        world_seed = int(self.rng.integers(2**31))
        if self.routes:
            self.world.reset(world_seed, self.starts)
        else:
            self.world.reset(world_seed)  # the map's spawn places
        for car in range(self.world.cars):
            self.world.command(car, 0.0, 0.0)
        self.agents = list(self.possible_agents)
        self.steps = 0
        poses = self._poses()
        for car in range(self.world.cars):
            o = self.world.observe_raw(car)
            self.progress[car] = o.route_progress_m if self.routes else 0.0
        obs = {a: self._obs(self._car(a), poses) for a in self.agents}
        return obs, {a: {} for a in self.agents}

    def step(self, actions: dict[str, ObsArray]) -> StepResult:
        for a in self.agents:
            act = np.clip(np.asarray(actions.get(a, (0.0, 0.0)), dtype=np.float64), -1.0, 1.0)
            self.world.command(self._car(a), float(act[0]), float(act[1]))
        self.world.step(self.period_ms)
        self.steps += 1
        poses = self._poses()
        obs, rew, term, trunc, info = {}, {}, {}, {}, {}
        for a in self.agents:
            car = self._car(a)
            o = self.world.observe_raw(car)
            if self.routes:
                now = float(o.route_progress_m)
                done_route = now > float(o.route_length_m) - ROUTE_END_M
            else:  # forward distance this step
                now = self.progress[car] + float(o.vel_body_m_s[0]) * self.period_ms * 1e-3
                done_route = False
            reward = now - float(self.progress[car])
            self.progress[car] = now
            if o.in_collision:
                reward -= 10.0
            obs[a] = self._obs(car, poses)
            rew[a] = float(reward)
            term[a] = bool(o.in_collision or o.off_lane or done_route)
            trunc[a] = self.steps >= self.max_steps
            info[a] = {"in_collision": bool(o.in_collision), "off_lane": bool(o.off_lane)}
        for a in list(self.agents):
            if term[a] or trunc[a]:
                self.world.command(self._car(a), 0.0, 0.0)
                self.agents.remove(a)
        return obs, rew, term, trunc, info

    def render(self) -> None:
        return None

    def close(self) -> None:
        self.world.close()
