"""Scores a smart-city run from the simulator's ground truth and light states (never from what
the cars believe): red-light and stop-sign violations, stop-line overshoot, collisions, the
smallest gap between cars and the laps each car drove. The stop points come from the map's
sidecar JSON by the behaviour layer's rule: a light's stop line; a stop sign's lane's stop line,
or the sign's place on its lane when the lane has none."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from autodrive.core import vehicle
from autodrive.core.geometry import wrap

HEADING_TOL_RAD = math.radians(45.0)
LATERAL_TOL_M = 0.2  # a car within this of a stop line's centre is on its lane
# A car stands while its body stays within this of where it stopped [m]. Judged by position, not
# by the body's speed: that wobbles above 1 cm/s as the body settles after braking.
STILL_M = 0.003
NEAR_BEFORE_M = 0.25  # a standstill this close before a stop point counts as stopping there
STOP_SIGN_HOLD_S = 1.0
# A standstill counts as a stop at a line (for overshoot) once it lasted this long [s of sim
# time]: a ground-truth sample repeated while a car pulls away over the line is no stop (it
# had scored a car driving off a stop sign at 0.2 m/s as a 0.30 m overshoot).
MIN_STOP_S = 0.2
RED = 1


@dataclass(frozen=True)
class StopPoint:
    name: str
    x_m: float
    y_m: float
    heading_rad: float  # the lane's direction at the stop
    light_id: int  # -1: a stop sign


def front_offset_m() -> float:
    """base_link (rear axle) to the front bumper [m], from vehicle/nigel.params."""
    car = vehicle.load()
    return float(car.vector("chassis_offset_m")[0] + 0.5 * car.vector("chassis_size_m")[0])


def front_past_m(x: float, y: float, yaw: float, p: StopPoint) -> float:
    """How far the car's front is past p along p's lane [m] (< 0: before it)."""
    f = front_offset_m()
    fx, fy = x + f * math.cos(yaw), y + f * math.sin(yaw)
    return (fx - p.x_m) * math.cos(p.heading_rad) + (fy - p.y_m) * math.sin(p.heading_rad)


def on_approach(x: float, y: float, yaw: float, p: StopPoint) -> bool:
    """The car drives p's lane near p (heading and lateral offset)."""
    if abs(wrap(yaw - p.heading_rad)) > HEADING_TOL_RAD:
        return False
    lateral = -(x - p.x_m) * math.sin(p.heading_rad) + (y - p.y_m) * math.cos(p.heading_rad)
    return abs(lateral) < LATERAL_TOL_M


@dataclass
class MapFacts:
    lanes: dict[str, list[dict[str, float]]]
    stops: list[StopPoint]

    @staticmethod
    def load(map_json: Path) -> "MapFacts":
        d = json.loads(map_json.read_text())
        lanes = {lane["name"]: lane["centre_line"] for lane in d["lanes"]}
        lines = {s["name"]: s for s in d["stop_lines"]}

        def heading_at(lane: str, x: float, y: float) -> float:
            pts = lanes[lane]
            best = min(pts, key=lambda q: (q["x_m"] - x) ** 2 + (q["y_m"] - y) ** 2)
            return float(best["heading_rad"])

        def on_lane(lane: str, x: float, y: float) -> tuple[float, float]:
            pts = lanes[lane]
            best = min(pts, key=lambda q: (q["x_m"] - x) ** 2 + (q["y_m"] - y) ** 2)
            return float(best["x_m"]), float(best["y_m"])

        stops = []
        for t in d["traffic_lights"]:
            sl = lines[t["stop_line"]]
            x, y = sl["centre_m"]
            stops.append(StopPoint(sl["name"], x, y, heading_at(t["lane"], x, y), t["id"]))
        for s in d["signs"]:
            if s["kind"] != "stop":
                continue
            own = [sl for sl in d["stop_lines"] if sl["lane"] == s["lane"]]
            x, y = own[0]["centre_m"] if own else on_lane(s["lane"], *s["position_m"])
            name = own[0]["name"] if own else s["name"]
            stops.append(StopPoint(name, x, y, heading_at(s["lane"], x, y), -1))
        return MapFacts(lanes, stops)

    def stop_for_light(self, light_id: int) -> StopPoint:
        return next(s for s in self.stops if s.light_id == light_id)

    def stop_sign_points(self) -> list[StopPoint]:
        return [s for s in self.stops if s.light_id < 0]

    def lane_point(self, lane: str, back_from_end_m: float) -> tuple[float, float, float]:
        """The pose on lane's centre line back_from_end_m before its end [m, m, rad]."""
        pts = self.lanes[lane]
        left = back_from_end_m
        for a, b in zip(reversed(pts[:-1]), reversed(pts[1:])):
            seg = math.dist((a["x_m"], a["y_m"]), (b["x_m"], b["y_m"]))
            if seg >= left:
                u = 1.0 - left / seg
                x = a["x_m"] + u * (b["x_m"] - a["x_m"])
                y = a["y_m"] + u * (b["y_m"] - a["y_m"])
                return x, y, float(a["heading_rad"])
            left -= seg
        return pts[0]["x_m"], pts[0]["y_m"], pts[0]["heading_rad"]


@dataclass
class CarScore:
    """Per car: the state of the scoring as its ground truth streams in."""

    start: tuple[float, float] | None = None
    away: bool = False
    laps: int = 0
    lap_starts_s: list[float] = field(default_factory=list)
    prev_past: dict[str, float] = field(default_factory=dict)
    still_since_s: float | None = None
    still_anchor: tuple[float, float] | None = None  # where the current standstill began [m]
    still_at: dict[str, float] = field(default_factory=dict)  # stop -> longest standstill [s]
    in_collision: bool = False
    driven_m: float = 0.0
    at: tuple[float, float] | None = None
    t_s: float = 0.0
    # standing away from every stop point (an obstacle, a car ahead) since [s]; the longest [s]
    held_since_s: float | None = None
    longest_held_s: float = 0.0


# A car standing this long [s sim] away from every stop point is reported blocked: the live
# mission and the rescore of its log judge by the same figure.
BLOCKED_S = 30.0


class Scorer:
    """Feed it ground truth and light states in time order; read report()."""

    def __init__(
        self,
        facts: MapFacts,
        lap_radius_m: float = 0.25,
        away_m: float = 1.5,
        blocked_s: float = math.inf,
    ) -> None:
        self.facts = facts
        self.lights: dict[int, int] = {}
        self.cars: dict[str, CarScore] = {}
        self.last: dict[str, tuple[float, float, float]] = {}
        self.red_violations: list[dict[str, Any]] = []
        self.sign_violations: list[dict[str, Any]] = []
        self.overshoot_m = 0.0
        self.overshoot_at: dict[str, Any] | None = None  # where the largest overshoot stood
        self.front_past_max_m = -math.inf  # signed: how close the fronts came (< 0: before)
        self.crossings = {"after_red_stop": 0, "after_stop_sign_stop": 0, "on_green_or_yellow": 0}
        self.collisions = 0
        self.min_gap_m = math.inf
        self.lap_radius_m, self.away_m = lap_radius_m, away_m
        self.blocked_s = blocked_s  # standing this long away from every stop point: blocked [s]

    def light(self, light_id: int, state: int) -> None:
        self.lights[light_id] = state

    def truth(self, car: str, t_s: float, x: float, y: float, yaw: float, hit: bool) -> None:
        c = self.cars.setdefault(car, CarScore())
        if c.start is None:
            c.start = (x, y)
            c.lap_starts_s.append(t_s)
        d0 = math.dist((x, y), c.start)
        if d0 > self.away_m:
            c.away = True
        elif c.away and d0 < self.lap_radius_m:
            c.away = False
            c.laps += 1
            c.lap_starts_s.append(t_s)
        if c.at is not None:
            c.driven_m += math.dist(c.at, (x, y))
        c.at = (x, y)
        if hit and not c.in_collision:
            self.collisions += 1
        c.in_collision = hit
        moved = c.still_anchor is None or math.dist(c.still_anchor, (x, y)) > STILL_M
        if moved:  # a standstill can begin here
            c.still_anchor, c.still_since_s = (x, y), t_s
        standing = not moved
        c.t_s = t_s
        at_stop = False
        for p in self.facts.stops:
            if not on_approach(x, y, yaw, p):
                c.prev_past.pop(p.name, None)
                continue
            past = front_past_m(x, y, yaw, p)
            at_stop = at_stop or -NEAR_BEFORE_M < past < 0.3
            if standing and -NEAR_BEFORE_M < past < 0.3 and c.still_since_s is not None:
                held = t_s - c.still_since_s
                c.still_at[p.name] = max(c.still_at.get(p.name, 0.0), held)
                red = self.lights.get(p.light_id) == RED
                if held >= MIN_STOP_S and (p.light_id < 0 or red or held > 0.5):
                    if past > self.overshoot_m:
                        self.overshoot_at = {"car": car, "t_s": round(t_s, 2), "stop": p.name,
                                             "light_state": self.lights.get(p.light_id, -1)}  # fmt: skip
                    self.overshoot_m = max(self.overshoot_m, past)
                    self.front_past_max_m = max(self.front_past_max_m, past)
            prev = c.prev_past.get(p.name)
            if prev is not None and prev < 0.0 <= past:  # the front crosses the line now
                event = {"car": car, "t_s": round(t_s, 2), "stop": p.name}
                if p.light_id >= 0 and self.lights.get(p.light_id) == RED:
                    self.red_violations.append({**event, "light": p.light_id})
                held = c.still_at.get(p.name, 0.0)
                if p.light_id < 0 and held < STOP_SIGN_HOLD_S:
                    self.sign_violations.append(event)
                elif p.light_id < 0:
                    self.crossings["after_stop_sign_stop"] += 1
                elif held > 0.5:
                    self.crossings["after_red_stop"] += 1
                else:
                    self.crossings["on_green_or_yellow"] += 1
                c.still_at.pop(p.name, None)
            c.prev_past[p.name] = past
        if standing and not at_stop:
            if c.held_since_s is None:  # standing since its standstill began
                c.held_since_s = t_s if c.still_since_s is None else c.still_since_s
            c.longest_held_s = max(c.longest_held_s, t_s - c.held_since_s)
        else:
            c.held_since_s = None
        self.last[car] = (x, y, yaw)
        for other, (ox, oy, oyaw) in self.last.items():
            # cars going the same way (one behind the other), not cars passing in the other lane
            if other != car and abs(wrap(yaw - oyaw)) < HEADING_TOL_RAD:
                self.min_gap_m = min(self.min_gap_m, math.dist((x, y), (ox, oy)))

    def report(self) -> dict[str, Any]:
        laps = [c.laps for c in self.cars.values()]
        lap_s = [
            b - a for c in self.cars.values() for a, b in zip(c.lap_starts_s, c.lap_starts_s[1:])
        ]
        length_m = vehicle.load().envelope_length_m
        return {
            "red_light_violations": len(self.red_violations),
            "stop_sign_violations": len(self.sign_violations),
            "max_stop_line_overshoot_m": round(self.overshoot_m, 4),
            # which car stood so, at which stop and sim time [s], the light's state (-1: a sign)
            "max_stop_line_overshoot_at": self.overshoot_at,
            # the closest any front came to a stop point it stood at (< 0: before the line) [m]
            "stop_front_past_max_m": (
                round(self.front_past_max_m, 4) if math.isfinite(self.front_past_max_m) else None
            ),
            # stop-line crossings: after standing at a light (> 0.5 s), after a stop-sign stop
            # (>= 1 s), or without stopping (green or yellow)
            "stop_line_crossings": dict(self.crossings),
            "collisions": self.collisions,
            # two cars going the same way: base_link to base_link less one car length (the
            # bumper gap of two cars in line); None when no two cars ever drove the same way
            "min_gap_m": (
                round(self.min_gap_m - length_m, 3) if math.isfinite(self.min_gap_m) else None
            ),
            "laps_completed": min(laps) if laps else 0,
            "laps_per_car": {k: c.laps for k, c in sorted(self.cars.items())},
            "driven_m": {k: round(c.driven_m, 2) for k, c in sorted(self.cars.items())},
            "mean_lap_s": round(sum(lap_s) / len(lap_s), 2) if lap_s else None,
            # the longest standstill of each car away from every stop line (an obstacle ahead, a
            # car ahead) [s], and the cars standing so now for blocked_s or more
            "longest_standstill_away_s": {
                k: round(c.longest_held_s, 1) for k, c in sorted(self.cars.items())
            },
            "blocked": sorted(
                k
                for k, c in self.cars.items()
                if c.held_since_s is not None and c.t_s - c.held_since_s >= self.blocked_s
            ),
            "violations": self.red_violations + self.sign_violations,
        }
