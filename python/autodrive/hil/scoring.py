"""Figures of a run against the simulator's ground truth: final pose errors, localisation RMS,
dead-reckoning drift, clearance to obstacles. Pure functions of the recorded samples."""

from __future__ import annotations

import bisect
import math
from collections.abc import Sequence

from autodrive.core.geometry import (
    Alignment,
    Pose,
    Rect,
    polygon_distance,
    rect_corners,
    to_world,
    wrap,
)
from autodrive.core.vehicle import Vehicle

# a stamped estimate: (t [us, sim time], x [m], y [m], yaw [rad])
Stamped = tuple[int, float, float, float]
# a track point: (t [us], x [m], y [m])
TrackPoint = tuple[int, float, float]


def rms(values: Sequence[float]) -> float:
    return math.sqrt(sum(v * v for v in values) / len(values))


def nearest_index(stamps: Sequence[int], t: float) -> int:
    """Index of the first stamp at or after t, the last one if none."""
    return min(max(bisect.bisect_left(stamps, t), 0), len(stamps) - 1)


def final_errors(final: Sequence[float], goal: Sequence[float]) -> tuple[float, float]:
    """(position error [m], heading error [deg]) of the final pose against the goal."""
    return (
        math.hypot(final[0] - goal[0], final[1] - goal[1]),
        abs(math.degrees(wrap(final[2] - goal[2]))),
    )


def localisation_errors(
    estimates: Sequence[Stamped], gt_t: Sequence[int], gt: Sequence[Pose], start: Sequence[float]
) -> list[float]:
    """Position error [m] of each estimate (in the start frame) against the truth at its own
    stamp (the scan's mid-time: both are sim time [us]), not at its arrival."""
    errs = []
    for t, x, y, yaw in estimates:
        i = nearest_index(gt_t, t)
        w = to_world(start, (x, y, yaw))
        errs.append(math.hypot(w[0] - gt[i][0], w[1] - gt[i][1]))
    return errs


def aligned_track(
    samples: Sequence[Stamped],
    gt_t: Sequence[int],
    gt: Sequence[Pose],
    span: tuple[int, int] | None,
) -> list[TrackPoint] | None:
    """An odometry track in the world, aligned with the truth at its first sample inside span
    (sim-time stamps [us]): dead reckoning from a known start. None if fewer than two samples."""
    if not span:
        return None
    inside = [s for s in samples if span[0] <= s[0] <= span[1]]
    if len(inside) < 2:
        return None
    t0, x0, y0, yaw0 = inside[0]
    align = Alignment((x0, y0, yaw0), gt[nearest_index(gt_t, t0)])
    return [(t, *align.point(x, y)) for t, x, y, _ in inside]


def odometry_drift(
    track: Sequence[TrackPoint], gt_t: Sequence[int], gt: Sequence[Pose]
) -> tuple[float, float | None]:
    """(final position error [m], as % of the distance driven) of an aligned track."""
    i0 = bisect.bisect_left(gt_t, track[0][0])
    i1 = nearest_index(gt_t, track[-1][0])
    err = math.hypot(track[-1][1] - gt[i1][0], track[-1][2] - gt[i1][1])
    dist = sum(math.hypot(b[0] - a[0], b[1] - a[1]) for a, b in zip(gt[i0:i1], gt[i0 + 1 : i1 + 1]))
    return round(err, 4), round(100.0 * err / dist, 2) if dist > 0.05 else None


def min_clearance(
    gt: Sequence[Pose], vehicle: Vehicle, obstacles: Sequence[Rect], stride: int = 10
) -> float:
    """Smallest gap [m] between the car's envelope and any obstacle over the run (every
    stride-th truth sample; a late box counts all run long)."""
    obs = [rect_corners(o) for o in obstacles]
    best = float("inf")
    for pose in gt[::stride]:
        car = rect_corners(vehicle.envelope.at(pose))
        for o in obs:
            best = min(best, polygon_distance(car, o))
    return best
