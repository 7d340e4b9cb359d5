"""The rule-based crossing: every car follows its route with the lane follower at full
throttle; the conflict zone (the box inside the stop lines) is granted first come, first
served, using the cars' intents (their routes, as V2V's route field carries them). A car asks
for the zone REQUEST_M before it, and enters only when every car whose path within the zone
conflicts with its own and that asked earlier (ties: the lower id) has left the zone."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from autodrive.core import vehicle
from autodrive.learn.marl.env import STOP_LINE_M, distance_from_centre, follow_steering

if TYPE_CHECKING:
    from autodrive.learn.marl.env import MarlIntersectionEnv

REQUEST_M = 0.45  # ask this far before the car's front reaches the zone [m]
STOP_BEFORE_M = 0.06  # a waiting car's front stops this far before the zone [m]
CONFLICT_MARGIN_M = 0.08  # paths closer than the footprint plus this conflict [m]


def _zone_arcs(points: npt.NDArray[np.float64]) -> tuple[float, float]:
    """(remaining length at the zone's entry, at its exit) along a route's points."""
    seg = np.hypot(*np.diff(points, axis=0).T)
    remaining = np.concatenate([np.cumsum(seg[::-1])[::-1], [0.0]])
    inside = np.nonzero(
        [distance_from_centre(float(x), float(y)) <= STOP_LINE_M for x, y in points]
    )[0]
    return float(remaining[inside[0]]), float(remaining[inside[-1]])


class FcfsBaseline:
    """env.baseline: commands for every car from the rule above."""

    def __init__(self) -> None:
        v = vehicle.load()
        size, offset = v.vector("chassis_size_m"), v.vector("chassis_offset_m")
        self.front_m = offset[0] + 0.5 * size[0]  # base_link to the front bumper
        self.rear_m = 0.5 * size[0] - offset[0]  # base_link to the rear bumper
        self.contact_m = math.hypot(size[0], size[1])  # any two footprints' centre distance
        self.entry: list[float] = []
        self.exit: list[float] = []
        self.conflict: npt.NDArray[np.bool_] = np.zeros((0, 0), dtype=bool)
        self.request: list[int | None] = []
        self.granted: list[bool] = []
        self.cleared: list[bool] = []

    def reset(self, env: MarlIntersectionEnv) -> None:
        n = env.n_cars
        arcs = [_zone_arcs(t.points_m) for t in env.trips]
        self.entry = [a[0] for a in arcs]
        self.exit = [a[1] for a in arcs]
        inside = [
            t.points_m[
                [
                    distance_from_centre(float(x), float(y)) <= STOP_LINE_M + 0.2
                    for x, y in t.points_m
                ]
            ]
            for t in env.trips
        ]
        self.conflict = np.zeros((n, n), dtype=bool)
        for i in range(n):
            for j in range(i + 1, n):
                d = np.hypot(*(inside[i][:, None, :] - inside[j][None, :, :]).transpose(2, 0, 1))
                self.conflict[i, j] = self.conflict[j, i] = bool(
                    d.min() < self.contact_m + CONFLICT_MARGIN_M
                )
        self.request = [None] * n
        self.granted = [False] * n
        self.cleared = [False] * n

    def commands(self, env: MarlIntersectionEnv) -> list[tuple[float, float]]:
        out = []
        for i, t in enumerate(env.trips):
            to_entry = t.remaining_m - self.entry[i] - self.front_m  # front to the zone [m]
            if t.remaining_m < self.exit[i] - self.rear_m:
                self.cleared[i] = True
            if self.request[i] is None and to_entry < REQUEST_M:
                self.request[i] = env.steps
        for i in range(env.n_cars):
            if self.granted[i] or self.request[i] is None:
                continue
            mine = (self.request[i], i)
            self.granted[i] = not any(
                self.conflict[i, j]
                and self.request[j] is not None
                and (self.request[j], j) < mine
                and not self.cleared[j]
                for j in range(env.n_cars)
            )
        for i, t in enumerate(env.trips):
            steering = follow_steering(env.cars_now[i], env.waypoint(i))
            to_entry = t.remaining_m - self.entry[i] - self.front_m
            wait = not self.granted[i] and to_entry < REQUEST_M and to_entry > -0.05
            throttle = 0.0 if wait and to_entry < STOP_BEFORE_M + 0.15 else 1.0
            out.append((throttle, steering))
        return out
