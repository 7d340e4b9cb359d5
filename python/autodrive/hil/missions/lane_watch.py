"""The cloning evaluation's referee: where a car is on its route's lane, from ground truth and the
map's lane data (autodrive.maps). Signed offsets of base_link and of the four wheels from
the route's centre line, a crossing of the lane bound by any wheel (an intervention in the
PilotNet sense), laps from the distance driven along the route; a stall (sim time without
progress along the route, which a safety driver would take over too: an intervention) and the
autonomy figure they give."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

from autodrive.core import vehicle
from autodrive.maps.description import Route

Pose3 = tuple[float, float, float]  # x [m], y [m], yaw [rad]
INTERVENTION_COST_S = 6.0  # PilotNet: each intervention costs 6 s of autonomy
STALL_S = 6.0  # this long of sim time with less than STALL_PROGRESS_M along the route: a stall
STALL_PROGRESS_M = 0.05


def takeover_due(wheel_margin_m: float, takeover_margin_m: float | None) -> bool:
    """DAgger's takeover rule (tools/pilot dagger): the expert takes over where the car would
    leave the lane, a wheel within takeover_margin_m [m] of the lane bound (or over it); never
    without a margin (None: a mission's referee, which intervenes at the bound only).
    ValueError for a negative margin (a takeover outside the lane takes over nothing)."""
    if takeover_margin_m is None:
        return False
    if not takeover_margin_m >= 0.0:
        raise ValueError(f"takeover margin {takeover_margin_m} m: must be >= 0")
    return wheel_margin_m < takeover_margin_m


def autonomy_pct(interventions: int, elapsed_s: float) -> float | None:
    """PilotNet's autonomy, 100 (1 - interventions x 6 s / elapsed) [%], never below 0; None
    before any time has elapsed."""
    if elapsed_s <= 0:
        return None
    return max(0.0, 100.0 * (1.0 - interventions * INTERVENTION_COST_S / elapsed_s))


@dataclass
class StallWatch:
    """Counts a stall each STALL_S of sim time in which the car gained less than
    STALL_PROGRESS_M along its route (standing, or driving the wrong way)."""

    since_s: float | None = None  # start of the current window [s of sim time]
    since_progress_m: float = 0.0
    stalls: int = 0

    def update(self, t_s: float, progress_m: float) -> bool:
        """True when this sample ends a stalled window (one more intervention)."""
        if self.since_s is None or progress_m - self.since_progress_m >= STALL_PROGRESS_M:
            self.since_s, self.since_progress_m = t_s, progress_m
            return False
        if t_s - self.since_s < STALL_S:
            return False
        self.stalls += 1
        self.since_s, self.since_progress_m = t_s, progress_m
        return True


@dataclass
class LaneWatch:
    """Follows one car along one route, one ground-truth pose at a time."""

    route: Route
    wheel_points_m: list[tuple[float, float]]  # wheel contact points in base_link [m]
    progress_m: float = 0.0  # driven along the route (unwrapped; laps = progress / length)
    last_s_m: float | None = None
    offsets_m: list[float] = field(default_factory=list)  # base_link, + left of the line
    _a: npt.NDArray[np.float64] = field(init=False)
    _d: npt.NDArray[np.float64] = field(init=False)
    _len2: npt.NDArray[np.float64] = field(init=False)
    _s0: npt.NDArray[np.float64] = field(init=False)

    def __post_init__(self) -> None:
        pts = np.asarray(self.route.polyline_m, dtype=float)
        self._a = pts[:-1]
        self._d = pts[1:] - pts[:-1]
        self._len2 = np.maximum((self._d**2).sum(axis=1), 1e-12)
        seg = np.sqrt(self._len2)
        self._s0 = np.concatenate(([0.0], np.cumsum(seg)[:-1]))

    @property
    def length_m(self) -> float:
        return float(self._s0[-1] + math.sqrt(self._len2[-1]))

    @property
    def laps(self) -> float:
        return self.progress_m / self.length_m

    def locate(self, x: float, y: float) -> tuple[float, float, Pose3]:
        """(signed offset [m, + left], along [m], nearest centre-line pose) of a point."""
        p = np.array([x, y])
        t = np.clip(((p - self._a) * self._d).sum(axis=1) / self._len2, 0.0, 1.0)
        q = self._a + t[:, None] * self._d
        dist2 = ((q - p) ** 2).sum(axis=1)
        i = int(np.argmin(dist2))
        dx, dy = self._d[i]
        side = dx * (y - self._a[i][1]) - dy * (x - self._a[i][0])
        offset = math.copysign(math.sqrt(float(dist2[i])), side)
        along = float(self._s0[i] + t[i] * math.sqrt(self._len2[i]))
        return offset, along, (float(q[i][0]), float(q[i][1]), math.atan2(dy, dx))

    def wheels_out(self, pose: Pose3) -> bool:
        """True when any wheel's contact point is past the lane bound (route half width)."""
        return self.wheel_margin_m(pose) < 0.0

    def wheel_margin_m(self, pose: Pose3) -> float:
        """[m] from the lane bound to the wheel nearest it (its tyre's outer edge), inward;
        below 0 when that wheel is over the bound."""
        x, y, yaw = pose
        c, s = math.cos(yaw), math.sin(yaw)
        worst = math.inf
        for wx, wy in self.wheel_points_m:
            off, _, _ = self.locate(x + c * wx - s * wy, y + s * wx + c * wy)
            worst = min(worst, self.route.half_width_m - abs(off))
        return worst

    def update(self, pose: Pose3) -> float:
        """Follows the car to pose: progress along the route; returns base_link's offset [m]."""
        off, along, _ = self.locate(pose[0], pose[1])
        if self.last_s_m is not None:
            step = along - self.last_s_m
            if self.route.loop:  # across the loop's seam
                step = (step + self.length_m / 2) % self.length_m - self.length_m / 2
            self.progress_m += step
        self.last_s_m = along
        self.offsets_m.append(off)
        return off

    def cross_track_rms_m(self) -> float:
        if not self.offsets_m:
            return float("nan")
        return float(np.sqrt(np.mean(np.square(self.offsets_m))))


def for_route(route: Route) -> LaneWatch:
    """A watch with the car's wheel contact points from the vehicle description: rear wheels on
    the rear axle (base_link), front wheels a wheelbase ahead, each at half the track plus half a
    wheel width to the side (the outer edge of the tyre)."""
    car = vehicle.load()
    wb, half = car.number("wheelbase_m"), 0.5 * (
        car.number("track_m") + car.number("wheel_width_m")
    )
    return LaneWatch(route, [(0.0, half), (0.0, -half), (wb, half), (wb, -half)])
