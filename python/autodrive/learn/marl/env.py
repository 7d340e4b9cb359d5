"""The paper's intersection task as a PettingZoo parallel environment on Intersection School,
over the learning API (every car the HIL car with its emulated Nano). Observation: the C core's
layout v1 (goal and route waypoint relative to self, own speed and steering, the nearest peers'
relative position, yaw and speed). Actions: discrete steering {-1, 0, 1} at constant throttle
(optionally throttle {0.5, 1.0}), or continuous steering with a steering-rate penalty. Reward:
+1 at the goal; a collision (or leaving the road) gives -0.425 x the distance to the goal and
ends the car's episode; else the shaping term: the paper's 0.01 / (0.001 + distance)
(shaping="paper"), or PROGRESS_GAIN x the distance gained this step (shaping="progress", the
default). The paper's term pays every step spent near the goal, so with the shield in the loop a
car held 1 m from its goal for 30 s earns 3, more than arriving (about 2.3): training with it
learned to wait (returns of 3+ for timed-out cars). The progress term sums to the distance
driven towards the goal, whatever the time it took, so only arriving pays.

Episodes are drawn from the seed: each car a distinct approach, a turn (left, straight, right)
and a spawn time; a car spawned t s later starts t x its top speed further back on its approach
(all cars act from the first step). A car at its goal is done; it drives on along its route
under the baseline's lane follower so that it stays a real obstacle. With shield=True each
command goes through the core's time-to-collision shield first."""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field
from typing import Any

import gymnasium as gym
import numpy as np
import numpy.typing as npt
from pettingzoo import ParallelEnv

from autodrive.core import channels
from autodrive.gym import tasks
from autodrive.gym.pz_env import ObsArray, StepResult
from autodrive.gym.world import World
from autodrive.learn.marl.core import OBS_DIM, Car, Core, Lane, top_speed_m_s
from autodrive.core.geometry import wrap

MAP = "intersection_school"
APPROACHES = ("north", "east", "south", "west")
# turn of each (from, to): the routes are named <from>_to_<to>
TURNS = {"left": 1, "straight": 2, "right": 3}  # quarter turns clockwise from the approach
CONTROL_HZ = 10.0
STOP_LINE_M = 0.65  # the stop lines' distance from the centre (the conflict zone's edge)
START_M = 1.2  # the nearest start from the centre along the approach [m]
SPAWN_SPREAD_S = 4.0  # spawn times are uniform in [0, this] s
GOAL_M = 1.3  # the goal: this far from the centre on the exit lane [m]
GOAL_REACHED_M = 0.12  # base_link this close to the goal: arrived
LOOKAHEAD_M = 0.35  # the route waypoint of the observation
OFF_ROAD_FACTOR = 2.0  # |lateral offset| > this x the lane half width: left the road
COLLISION_FACTOR = 0.425
GOAL_REWARD = 1.0
SHAPING = 0.01
SHAPING_EPS_M = 0.001
PROGRESS_GAIN = 0.3  # progress shaping per m gained towards the goal (~0.7 over a trip)
SHAPINGS = ("progress", "paper")
MAX_STEPS = 300
STEER_RATE_PENALTY = 0.05  # continuous variant: per unit of |steering change| per step
FOLLOW_GAIN = 2.5  # the lane follower: steering = gain x waypoint bearing [rad]


def route_name(approach: str, turn: str) -> str:
    i = APPROACHES.index(approach)
    return f"{approach}_to_{APPROACHES[(i + TURNS[turn]) % 4]}"


def distance_from_centre(x: float, y: float) -> float:
    return max(abs(x), abs(y))


@dataclass
class CarRoute:
    """One car's trip this episode: its route cut to [start, goal] and the full polyline."""

    name: str
    points_m: npt.NDArray[np.float64]  # from the start to the end of the map's route
    goal_xy_m: tuple[float, float]
    start: tuple[float, float, float]
    spawn_s: float
    half_width_m: float = 0.0
    buffer: Any = None
    hint: int = -1
    remaining_m: float = 0.0
    extras: dict[str, float] = field(default_factory=dict)


def plan_route(name: str, spawn_s: float) -> CarRoute:
    r = tasks.route(MAP, name)
    pts = r.points_m
    d = np.array([distance_from_centre(float(x), float(y)) for x, y in pts])
    mid = int(np.argmin(d))
    back_m = START_M + spawn_s * top_speed_m_s()
    before = np.nonzero(d[:mid] >= back_m)[0]
    i0 = int(before[-1]) if len(before) else 0
    after = np.nonzero(d[mid:] >= GOAL_M)[0]
    ig = mid + int(after[0]) if len(after) else len(pts) - 1
    yaw = math.atan2(pts[i0 + 1][1] - pts[i0][1], pts[i0 + 1][0] - pts[i0][0])
    return CarRoute(
        name=name,
        half_width_m=r.half_width_m,
        points_m=pts[i0:].copy(),
        goal_xy_m=(float(pts[ig][0]), float(pts[ig][1])),
        start=(float(pts[i0][0]), float(pts[i0][1]), yaw),
        spawn_s=spawn_s,
    )


def follow_steering(car: Car, waypoint: tuple[float, float]) -> float:
    """The lane follower (baseline, finished cars): steer to the waypoint's bearing."""
    bearing = wrap(math.atan2(waypoint[1] - car.y_m, waypoint[0] - car.x_m) - car.yaw_rad)
    return float(np.clip(FOLLOW_GAIN * bearing, -1.0, 1.0))


class MarlIntersectionEnv(ParallelEnv[str, ObsArray, Any]):  # type: ignore[misc]
    """N cars (agents "nigel1".."nigelN", 1 <= N <= 4) crossing Intersection School.
    action_mode: "discrete" (Discrete(3): steering -1, 0, 1 at throttle 1), "discrete_throttle"
    (Discrete(6): steering x throttle {0.5, 1.0}) or "continuous" (Box steering in [-1, 1],
    steering-rate penalty). shield: commands pass the core's TTC shield. driver: None (the
    policy's actions), or "baseline" (the rule-based crossing drives, actions are ignored)."""

    metadata: dict[str, Any] = {"name": "autodrive_marl_intersection_v1", "render_modes": []}

    def __init__(
        self,
        cars: int = 4,
        action_mode: str = "discrete",
        shield: bool = False,
        max_steps: int = MAX_STEPS,
        render_mode: str | None = None,
        shaping: str = "progress",
        steer_rate_penalty: float = STEER_RATE_PENALTY,
    ) -> None:
        if not 1 <= cars <= len(APPROACHES):
            raise ValueError(f"cars: {cars}, the intersection takes 1..{len(APPROACHES)}")
        if action_mode not in ("discrete", "discrete_throttle", "continuous"):
            raise ValueError(
                f"action_mode '{action_mode}': one of discrete, discrete_throttle, continuous"
            )
        if shaping not in SHAPINGS:
            raise ValueError(f"shaping '{shaping}': one of {', '.join(SHAPINGS)}")
        self.shaping = shaping
        if not (math.isfinite(steer_rate_penalty) and steer_rate_penalty >= 0.0):
            raise ValueError(f"steer_rate_penalty {steer_rate_penalty}: a number >= 0")
        self.steer_rate_penalty = steer_rate_penalty
        self.n_cars = cars
        self.action_mode = action_mode
        self.use_shield = shield
        self.max_steps = max_steps
        self.render_mode = render_mode
        self.period_ms = round(1000.0 / CONTROL_HZ)
        self.period_s = self.period_ms / 1000.0
        self.world = World(MAP, cars=cars, seed=0)
        self.core = Core()
        self.steer_limit = float(self.core.shield_config.steer_limit_rad)
        self.possible_agents = [channels.vehicle_name(i + 1).lower() for i in range(cars)]
        self.agents: list[str] = []
        self.rng = np.random.default_rng()
        self.trips: list[CarRoute] = []
        self.cars_now: list[Car] = []
        self.last_steering = np.zeros(cars)
        self.last_distance = np.zeros(cars)
        self.steps = 0
        self.finished = [False] * cars
        self.stats: dict[str, Any] = {}
        self.baseline: Any = None

    @functools.lru_cache(maxsize=None)
    def observation_space(self, agent: str) -> gym.spaces.Space[Any]:
        return gym.spaces.Box(-np.inf, np.inf, (OBS_DIM,), np.float32)

    @functools.lru_cache(maxsize=None)
    def action_space(self, agent: str) -> gym.spaces.Space[Any]:
        if self.action_mode == "continuous":
            return gym.spaces.Box(-1.0, 1.0, (1,), np.float32)
        return gym.spaces.Discrete(6 if self.action_mode == "discrete_throttle" else 3)

    def command_of(self, action: Any) -> tuple[float, float]:
        """(throttle, steering) of an action."""
        if self.action_mode == "continuous":
            return 1.0, float(np.clip(np.asarray(action, dtype=np.float64).ravel()[0], -1, 1))
        a = int(action)
        if not 0 <= a < (6 if self.action_mode == "discrete_throttle" else 3):
            raise ValueError(f"action {a} outside the action space of mode {self.action_mode}")
        return (0.5 if a >= 3 else 1.0), float(a % 3 - 1)

    def _read_cars(self) -> list[Car]:
        out = []
        for i in range(self.n_cars):
            o = self.world.observe_raw(i)
            out.append(
                Car(
                    i + 1,
                    float(o.pos_m[0]),
                    float(o.pos_m[1]),
                    float(o.yaw_rad),
                    float(o.vel_body_m_s[0]),
                )
            )
        return out

    def _update_routes(self) -> None:
        for i, (t, c) in enumerate(zip(self.trips, self.cars_now)):
            wp, remaining, t.hint = self.core.route_waypoint(
                t.buffer, c.x_m, c.y_m, LOOKAHEAD_M, t.hint
            )
            t.extras["wp_x"], t.extras["wp_y"] = wp
            t.remaining_m = remaining

    def _goal_distance(self, i: int) -> float:
        c, g = self.cars_now[i], self.trips[i].goal_xy_m
        return math.hypot(g[0] - c.x_m, g[1] - c.y_m)

    def _obs(self, i: int) -> ObsArray:
        t = self.trips[i]
        return self.core.observation(
            self.cars_now[i],
            t.goal_xy_m,
            (t.extras["wp_x"], t.extras["wp_y"]),
            float(self.last_steering[i]),
            self.cars_now,
        )

    def waypoint(self, i: int) -> tuple[float, float]:
        t = self.trips[i]
        return t.extras["wp_x"], t.extras["wp_y"]

    def reset(
        self, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, ObsArray], dict[str, dict[str, Any]]]:
        if seed is not None:
            self.rng = np.random.default_rng(seed)
        approaches = self.rng.permutation(len(APPROACHES))[: self.n_cars]
        turns = list(TURNS)
        self.trips = []
        for a in approaches:
            turn = turns[int(self.rng.integers(len(turns)))]
            spawn = float(self.rng.uniform(0.0, SPAWN_SPREAD_S))
            self.trips.append(plan_route(route_name(APPROACHES[int(a)], turn), spawn))
        for t in self.trips:
            t.buffer = self.core.route_buffer(t.points_m)
        self.world.reset(int(self.rng.integers(2**31)), [t.start for t in self.trips])
        for i, t in enumerate(self.trips):
            self.world.set_route_points(i, t.points_m, tasks.route(MAP, t.name).half_width_m, False)
            self.world.command(i, 0.0, 0.0)
        self.agents = list(self.possible_agents)
        self.steps = 0
        self.finished = [False] * self.n_cars
        self.last_steering[:] = 0.0
        self.cars_now = self._read_cars()
        self._update_routes()
        self.last_distance = np.array([self._goal_distance(i) for i in range(self.n_cars)])
        self.stats = {
            "routes": [t.name for t in self.trips],
            "spawn_s": [t.spawn_s for t in self.trips],
            "outcome": ["running"] * self.n_cars,
            "traverse_s": [math.nan] * self.n_cars,
            "shield_interventions": 0,
            "shield_lane_steers": 0,
            "steering_rate_sq_sum": 0.0,
            "steering_rate_n": 0,
            "trajectories": [[(c.x_m, c.y_m)] for c in self.cars_now],
        }
        if self.baseline is not None:
            self.baseline.reset(self)
        obs = {a: self._obs(i) for i, a in enumerate(self.possible_agents)}
        return obs, {a: {} for a in self.agents}

    def step(self, actions: dict[str, Any]) -> StepResult:
        steer_before = np.array(
            [self.world.observe_raw(i).steering_rad for i in range(self.n_cars)]
        )
        baseline_cmds = self.baseline.commands(self) if self.baseline is not None else None
        sent = np.zeros(self.n_cars)
        for i, a in enumerate(self.possible_agents):
            me = self.cars_now[i]
            if self.finished[i]:
                throttle, steering = 1.0, follow_steering(me, self.waypoint(i))
                if self.trips[i].remaining_m < 0.2:
                    throttle = 0.0
            elif a not in self.agents:  # collided, off the road or out of time: stop
                throttle, steering = 0.0, 0.0
            elif baseline_cmds is not None:
                throttle, steering = baseline_cmds[i]
            else:
                if a not in actions:
                    raise ValueError(f"step: no action for agent '{a}'")
                throttle, steering = self.command_of(actions[a])
                if self.use_shield:
                    t = self.trips[i]
                    lane = Lane(
                        t.buffer, t.hint, t.half_width_m, steer_before[i] / self.steer_limit
                    )
                    r = self.core.shield(me, throttle, steering, self.cars_now, lane)
                    if r.intervened:
                        self.stats["shield_interventions"] += 1
                    if r.steered:
                        self.stats["shield_lane_steers"] += 1
                    throttle, steering = r.throttle, r.steering
            sent[i] = steering
            self.world.command(i, throttle, steering)
        self.world.step(self.period_ms)
        self.steps += 1
        self.cars_now = self._read_cars()
        self._update_routes()
        obs, rew, term, trunc, info = {}, {}, {}, {}, {}
        for i, a in enumerate(self.possible_agents):
            self.stats["trajectories"][i].append((self.cars_now[i].x_m, self.cars_now[i].y_m))
            if a not in self.agents:
                continue
            o = self.world.observe_raw(i)
            rate = (float(o.steering_rad) - steer_before[i]) / self.period_s
            self.stats["steering_rate_sq_sum"] += rate * rate
            self.stats["steering_rate_n"] += 1
            d = self._goal_distance(i)
            off_road = (
                bool(o.has_route)
                and abs(o.route_lateral_m) > OFF_ROAD_FACTOR * o.route_half_width_m
            )
            collided = bool(o.in_collision)
            passed = self.trips[i].remaining_m < self._remaining_at_goal(i) - GOAL_REACHED_M
            arrived = d < GOAL_REACHED_M or passed
            if self.shaping == "paper":
                reward = SHAPING / (SHAPING_EPS_M + d)
            else:
                reward = PROGRESS_GAIN * (self.last_distance[i] - d)
            self.last_distance[i] = d
            done = False
            if collided or off_road:
                reward = -COLLISION_FACTOR * d
                self.stats["outcome"][i] = "collision" if collided else "off_road"
                done = True
            elif arrived:
                reward = GOAL_REWARD
                self.stats["outcome"][i] = "goal"
                self.stats["traverse_s"][i] = self.steps * self.period_s
                self.finished[i] = True
                done = True
            if self.action_mode == "continuous":
                reward -= self.steer_rate_penalty * abs(sent[i] - self.last_steering[i])
            self.last_steering[i] = sent[i]
            obs[a] = self._obs(i)
            rew[a] = float(reward)
            term[a] = done
            trunc[a] = (not done) and self.steps >= self.max_steps
            if trunc[a]:
                self.stats["outcome"][i] = "timeout"
            info[a] = {"outcome": self.stats["outcome"][i]}
        self.agents = [a for a in self.agents if not (term[a] or trunc[a])]
        return obs, rew, term, trunc, info

    def _remaining_at_goal(self, i: int) -> float:
        t = self.trips[i]
        if "goal_remaining" not in t.extras:
            pts = t.points_m
            g = np.asarray(t.goal_xy_m)
            k = int(np.argmin(np.hypot(*(pts - g).T)))
            seg = np.hypot(*np.diff(pts[k:], axis=0).T)
            t.extras["goal_remaining"] = float(seg.sum())
        return t.extras["goal_remaining"]

    def steering_rate_rms(self) -> float:
        n = self.stats.get("steering_rate_n", 0)
        return math.sqrt(self.stats["steering_rate_sq_sum"] / n) if n else 0.0

    def render(self) -> None:
        return None

    def close(self) -> None:
        self.world.close()
