"""Driving an imported map's routes in the simulator in process (autodrive.gym.World: real
MuJoCo, the emulated Nano): one car from each route's start, steered by the shared pure pursuit
(autodrive.core.pure_pursuit, the one the simulator's route driver and the city driver use) at a
steady throttle, judged by the simulator's own lane test (ad_obs_t.off_lane: base_link beyond
the route's half width) until it reaches the route's end. Sim time only."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from autodrive.core import pure_pursuit
from autodrive.gym.world import World

LOOKAHEAD_M = 0.20  # the simulator's route driver's default (SCRIPT_ROUTE_LOOKAHEAD_DEFAULT_M)
THROTTLE = 0.6
PERIOD_MS = 20
END_MARGIN_M = 0.15  # done this close to the route's end [m]
SPEED_FLOOR_M_S = 0.05  # a route is given length / this of sim time at most


@dataclass(frozen=True)
class Drive:
    route: str
    ok: bool
    reached_end: bool
    off_lane_steps: int
    max_lateral_m: float
    half_width_m: float
    sim_s: float
    collisions: int


def drive(
    map_xml: Path, route: str, points: list[tuple[float, float]], max_sim_s: float = math.inf
) -> Drive:
    """Drives the map's route on its MJCF, steering along points [m] (the route's polyline from
    the sidecar), for at most max_sim_s of sim time (else the route's length at 0.05 m/s)."""
    world = World(str(map_xml), cars=1)
    try:
        (x0, y0), (x1, y1) = points[0], points[1]
        world.reset(0, [(x0, y0, math.atan2(y1 - y0, x1 - x0))])
        world.set_route(0, route)
        tracker = pure_pursuit.PathTracker(points, loop=False)
        limit = pure_pursuit.default_vehicle().steer_limit_rad
        off = collisions = 0
        worst = 0.0
        obs = world.observe(0)
        budget_s = min(max_sim_s, tracker.length_m / SPEED_FLOOR_M_S)
        while obs.time_s < budget_s:
            steer = tracker.steer_nearest((obs.pos_m[0], obs.pos_m[1], obs.yaw_rad), LOOKAHEAD_M)
            world.command(0, THROTTLE, max(-1.0, min(1.0, steer / limit)))
            world.step(PERIOD_MS)
            obs = world.observe(0)
            off += int(obs.off_lane)
            collisions += int(obs.in_collision)
            worst = max(worst, abs(obs.route_lateral_m))
            if obs.route_progress_m >= obs.route_length_m - END_MARGIN_M:
                break
        reached = obs.route_progress_m >= obs.route_length_m - END_MARGIN_M
        return Drive(route, reached and off == 0 and collisions == 0, reached, off, worst,
                     obs.route_half_width_m, obs.time_s, collisions)  # fmt: skip
    finally:
        world.close()
