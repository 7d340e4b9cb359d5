"""The road network the advisories are computed on, built from the map description
(autodrive.maps): lane centre lines with their arc length, which lane follows which, and
where each light's stop line and each sign sit along the lanes that pass them.

A car is placed on a lane from its pose (nearest centre line within the lane's half width and
60 deg of its heading; its route, when known, and its last lane break ties), then the lanes
ahead are walked: its route's next lane, else the one successor; at a fork without a route
the walk stops (what lies beyond depends on the turn). Distances are along the lanes from the
car's pose point (base_link, the rear-axle centre)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

from autodrive.core.geometry import wrap
from autodrive.maps import MapDescription

STEP_M = 0.02  # centre-line sampling [m]
JOIN_M = 0.03  # lane ends closer than this join; an anchor closer than this is on the lane [m]
JOIN_RAD = 0.35  # and their headings differ by less than this [rad]
MAX_HEADING_RAD = math.radians(60.0)  # a car further off a lane's heading is not on it
HORIZON_M = 12.0  # how far ahead the walk looks [m]


@dataclass(frozen=True)
class Anchor:
    """A light's stop line or a sign on a lane, s_m along it."""

    kind: str  # "light" or "sign"
    id: int
    s_m: float
    sign_kind: str = ""
    speed_limit_m_s: float = -1.0


@dataclass
class LaneGeom:
    name: str
    pts: npt.NDArray[np.float64]  # (n, 3): x, y, heading
    s: npt.NDArray[np.float64]  # (n,) arc length [m]
    half_width_m: float
    successors: list[str] = field(default_factory=list)
    predecessors: list[str] = field(default_factory=list)
    anchors: list[Anchor] = field(default_factory=list)

    @property
    def length_m(self) -> float:
        return float(self.s[-1])


@dataclass(frozen=True)
class Place:
    lane: str
    s_m: float
    offset_m: float  # lateral distance to the centre line [m]


@dataclass(frozen=True)
class Ahead:
    """What the walk found ahead of a car (distances <0 / ids -1 when none)."""

    light_id: int = -1
    stop_line_distance_m: float = -1.0
    sign_id: int = -1
    sign_kind: str = ""
    sign_distance_m: float = -1.0
    speed_limit_m_s: float = -1.0


class RoadNet:
    def __init__(self, m: MapDescription) -> None:
        self.map = m
        self.lanes: dict[str, LaneGeom] = {}
        for lane in m.lanes():
            pts = np.array(m.centre_line(lane, STEP_M), dtype=np.float64)
            seg = np.hypot(np.diff(pts[:, 0]), np.diff(pts[:, 1]))
            s = np.concatenate([[0.0], np.cumsum(seg)])
            self.lanes[lane.name] = LaneGeom(lane.name, pts, s, lane.half_width_m)
        self._join()
        self.routes = {r.name: r.lanes for r in m.named_routes()}
        self.route_loops = {r.name: r.loop for r in m.named_routes()}
        for light in m.lights():
            stop = m.stop_line(light.stop_line)
            heading = self.lanes[stop.lane].pts[0, 2] if stop.lane in self.lanes else None
            self._attach(Anchor("light", light.id, 0.0), stop.centre_m, heading, stop.lane)
        specs = {s.id: s for s in m.signs}
        for sign in m.placed_signs():
            spec = specs[sign.id]
            limit = sign.speed_limit_m_s if sign.speed_limit_m_s is not None else -1.0
            anchor = Anchor("sign", sign.id, 0.0, sign.kind, limit)
            if spec.lane is not None and spec.along_m is not None:
                g = self.lanes[spec.lane]
                k = int(np.searchsorted(g.s, spec.along_m).clip(0, len(g.s) - 1))
                self._attach(anchor, (float(g.pts[k, 0]), float(g.pts[k, 1])), None, spec.lane)
            else:  # a sign at a pose faces its traffic: it belongs to the lane heading against it
                self._attach(anchor, sign.position_m, wrap(sign.yaw_rad + math.pi), None, 0.6)
        for g in self.lanes.values():
            g.anchors.sort(key=lambda a: a.s_m)
        # every lane point, for placing cars quickly
        self._all = np.concatenate([g.pts for g in self.lanes.values()])
        self._lane_of = np.concatenate(
            [np.full(len(g.pts), i) for i, g in enumerate(self.lanes.values())]
        )
        self._index = np.concatenate([np.arange(len(g.pts)) for g in self.lanes.values()])
        self._names = list(self.lanes)

    def _join(self) -> None:
        for a in self.lanes.values():
            for b in self.lanes.values():
                if a is b:
                    continue
                end, start = a.pts[-1], b.pts[0]
                if (
                    math.dist(end[:2], start[:2]) < JOIN_M
                    and abs(wrap(end[2] - start[2])) < JOIN_RAD
                ):
                    a.successors.append(b.name)
                    b.predecessors.append(a.name)

    def _attach(
        self,
        anchor: Anchor,
        point: tuple[float, float],
        heading: float | None,
        own_lane: str | None,
        reach_m: float = JOIN_M,
    ) -> None:
        """Puts anchor on every lane passing within reach_m of point in the same direction (lanes
        of one approach share their start: the stop line is on all of them)."""
        if own_lane is not None:
            g = self.lanes[own_lane]
            k = int(np.argmin(np.hypot(g.pts[:, 0] - point[0], g.pts[:, 1] - point[1])))
            heading = float(g.pts[k, 2])
        best: list[tuple[float, LaneGeom, int]] = []
        for g in self.lanes.values():
            d = np.hypot(g.pts[:, 0] - point[0], g.pts[:, 1] - point[1])
            k = int(np.argmin(d))
            if (
                d[k] < reach_m
                and heading is not None
                and abs(wrap(g.pts[k, 2] - heading)) < JOIN_RAD
            ):
                best.append((float(d[k]), g, k))
        if own_lane is None and best:  # a sign at a pose: the nearest lane and its twins
            dmin = min(b[0] for b in best)
            best = [b for b in best if b[0] < dmin + JOIN_M]
        for _, g, k in best:
            g.anchors.append(
                Anchor(
                    anchor.kind, anchor.id, float(g.s[k]), anchor.sign_kind, anchor.speed_limit_m_s
                )
            )

    # --- placing a car --------------------------------------------------------------------------

    def place(
        self, x_m: float, y_m: float, yaw_rad: float, route: str = "", last_lane: str = ""
    ) -> Place | None:
        """The lane the car is on, or None when it is on none."""
        d = np.hypot(self._all[:, 0] - x_m, self._all[:, 1] - y_m)
        near = np.nonzero(d < 0.35)[0]
        if len(near) == 0:
            return None
        dh = np.abs([wrap(a) for a in self._all[near, 2] - yaw_rad])
        near = near[dh < MAX_HEADING_RAD]
        best: dict[int, tuple[float, int]] = {}
        for i in near:
            lane = int(self._lane_of[i])
            if lane not in best or d[i] < best[lane][0]:
                best[lane] = (float(d[i]), int(self._index[i]))
        on_route = set(self.routes.get(route, []))
        follow = (
            {last_lane, *self.lanes[last_lane].successors} if last_lane in self.lanes else set()
        )
        scored = []
        for lane, (dist, k) in best.items():
            g = self.lanes[self._names[lane]]
            if dist > g.half_width_m + 0.05:
                continue
            # route lanes first, then the last lane and its successors, then the nearest
            rank = (g.name not in on_route, g.name not in follow, round(dist, 3))
            scored.append((rank, g, k, dist))
        if not scored:
            return None
        _, g, k, dist = min(scored, key=lambda t: t[0])
        hx, hy = math.cos(g.pts[k, 2]), math.sin(g.pts[k, 2])
        along = (x_m - g.pts[k, 0]) * hx + (y_m - g.pts[k, 1]) * hy
        s = float(np.clip(g.s[k] + along, 0.0, g.length_m))
        return Place(g.name, s, dist)

    # --- looking ahead --------------------------------------------------------------------------

    def next_lane(self, lane: str, route: str) -> str | None:
        lanes = self.routes.get(route)
        if lanes and lane in lanes:
            i = lanes.index(lane)
            if i + 1 < len(lanes):
                return lanes[i + 1]
            return lanes[0] if self.route_loops.get(route) else None
        succ = self.lanes[lane].successors
        return succ[0] if len(succ) == 1 else None

    def ahead(self, place: Place, route: str = "", horizon_m: float = HORIZON_M) -> Ahead:
        light: tuple[int, float] | None = None
        sign: tuple[int, str, float] | None = None
        lane, s0, travelled = place.lane, place.s_m, 0.0
        seen: set[str] = set()
        while travelled < horizon_m and (light is None or sign is None):
            g = self.lanes[lane]
            for a in g.anchors:
                if a.s_m < s0:
                    continue
                dist = travelled + a.s_m - s0
                if dist > horizon_m:
                    break
                if a.kind == "light" and light is None:
                    light = (a.id, dist)
                elif a.kind == "sign" and sign is None:
                    sign = (a.id, a.sign_kind, dist)
            travelled += g.length_m - s0
            seen.add(lane)
            nxt = self.next_lane(lane, route)
            if nxt is None or nxt in seen:
                break
            lane, s0 = nxt, 0.0
        return Ahead(
            light_id=light[0] if light else -1,
            stop_line_distance_m=light[1] if light else -1.0,
            sign_id=sign[0] if sign else -1,
            sign_kind=sign[1] if sign else "",
            sign_distance_m=sign[2] if sign else -1.0,
            speed_limit_m_s=self.speed_limit(place),
        )

    def speed_limit(self, place: Place) -> float:
        """The limit of the last speed-limit sign behind the car on its road: a limit holds from
        its sign to the next junction (a lane end where lanes fork or merge). -1 when none."""
        lane, s0 = place.lane, place.s_m
        for _ in range(64):
            g = self.lanes[lane]
            for a in reversed(g.anchors):
                if a.kind == "sign" and a.s_m <= s0 and a.speed_limit_m_s > 0:
                    return a.speed_limit_m_s
            if len(g.predecessors) != 1 or len(self.lanes[g.predecessors[0]].successors) != 1:
                return -1.0
            lane = g.predecessors[0]
            s0 = self.lanes[lane].length_m
        return -1.0
