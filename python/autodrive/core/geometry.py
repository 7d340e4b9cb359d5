"""Plane geometry of poses and rectangles: the one angle wrap, frame changes, the alignment of
a dead-reckoned track with the truth, distances between rectangles."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

# (x [m], y [m], yaw [rad])
Pose = tuple[float, float, float]
Point = tuple[float, float]
# a rectangle as (centre x [m], centre y [m], half x [m], half y [m], yaw [rad])
Rect = tuple[float, float, float, float, float]


def wrap(angle_rad: float) -> float:
    """The angle in [-pi, pi] (atan2's range) [rad]: the one angle wrap of the Python code (the
    generated maps' headings depend on its last bits)."""
    return math.atan2(math.sin(angle_rad), math.cos(angle_rad))


def to_frame(origin: Sequence[float], p: Sequence[float]) -> Pose:
    """World pose p expressed in the frame whose pose in the world is origin."""
    dx, dy = p[0] - origin[0], p[1] - origin[1]
    c, s = math.cos(origin[2]), math.sin(origin[2])
    return c * dx + s * dy, -s * dx + c * dy, wrap(p[2] - origin[2])


def to_world(origin: Sequence[float], p: Sequence[float]) -> Pose:
    """Pose p of the frame whose pose in the world is origin, expressed in the world."""
    c, s = math.cos(origin[2]), math.sin(origin[2])
    return (
        origin[0] + c * p[0] - s * p[1],
        origin[1] + s * p[0] + c * p[1],
        wrap(p[2] + origin[2]),
    )


def parse_pose_deg(text: str) -> Pose:
    """ "X,Y,YAW_DEG" as (x, y, yaw_rad) [m, m, rad]; ValueError saying what is wrong."""
    parts = text.split(",")
    if len(parts) != 3:
        raise ValueError("expected X,Y,YAW_DEG, e.g. -1.0,0.6,0")
    try:
        x, y, yaw_deg = (float(v) for v in parts)
    except ValueError:
        raise ValueError("X, Y and YAW_DEG must be numbers") from None
    if not all(map(math.isfinite, (x, y, yaw_deg))):
        raise ValueError("X, Y and YAW_DEG must be finite")
    return x, y, math.radians(yaw_deg)


@dataclass(frozen=True)
class Footprint:
    """A car's envelope: a rectangle centred centre_ahead_m ahead of the rear axle."""

    length_m: float
    width_m: float
    centre_ahead_m: float

    def at(self, pose: Sequence[float]) -> Rect:
        """The envelope at a rear-axle pose."""
        x, y, yaw = pose[0], pose[1], pose[2]
        return (
            x + self.centre_ahead_m * math.cos(yaw),
            y + self.centre_ahead_m * math.sin(yaw),
            self.length_m / 2,
            self.width_m / 2,
            yaw,
        )


class Alignment:
    """Maps an estimate's frame onto the truth's, so that the estimate's pose `estimate` lands
    on the truth's pose `truth` (dead reckoning from a known start)."""

    def __init__(self, estimate: Sequence[float], truth: Sequence[float]) -> None:
        self.estimate = estimate
        self.truth = truth
        self.dyaw_rad = wrap(truth[2] - estimate[2])
        self._c, self._s = math.cos(self.dyaw_rad), math.sin(self.dyaw_rad)

    def point(self, x: float, y: float) -> Point:
        dx, dy = x - self.estimate[0], y - self.estimate[1]
        return (
            self.truth[0] + self._c * dx - self._s * dy,
            self.truth[1] + self._s * dx + self._c * dy,
        )


def rect_corners(r: Rect) -> list[Point]:
    cx, cy, hx, hy, yaw = r
    c, s = math.cos(yaw), math.sin(yaw)
    return [
        (cx + c * dx - s * dy, cy + s * dx + c * dy)
        for dx, dy in ((hx, hy), (-hx, hy), (-hx, -hy), (hx, -hy))
    ]


def segment_distance(p: Point, a: Point, b: Point) -> float:
    ax, ay = b[0] - a[0], b[1] - a[1]
    t = max(0.0, min(1.0, ((p[0] - a[0]) * ax + (p[1] - a[1]) * ay) / (ax * ax + ay * ay)))
    return math.hypot(a[0] + t * ax - p[0], a[1] + t * ay - p[1])


def polygon_distance(pa: Sequence[Point], pb: Sequence[Point]) -> float:
    """Smallest vertex-to-edge distance between two closed polygons [m]; overlapping polygons
    are not detected (the simulator's collision flag catches those)."""
    d = float("inf")
    for p_, q_ in ((pa, pb), (pb, pa)):
        for p in p_:
            for i in range(len(q_)):
                d = min(d, segment_distance(p, q_[i], q_[(i + 1) % len(q_)]))
    return d
