"""Pure pursuit labels from the pose (labels.py), on Driving School's loop_ccw: on the centre
line of a straight the label is 0; left of it, it steers right, and a longer lookahead steers
less; on an arc of the loop the label is the arc's own steering, atan(wheelbase / radius), at
a lookahead shorter than the arc; the other lane (lane_shift 1) lies one lane width to the
left; a lookahead of 0 is refused. (That it reproduces the recorded expert's 0.2 m steering
needs a recording: tools/pilot train logs the RMS of relabelled minus recorded.)"""

from __future__ import annotations

import math

import numpy as np

from autodrive import maps
from autodrive.core import vehicle
from autodrive.learn.pilot import labels


def heading(line: np.ndarray, i: int) -> float:
    d = line[i + 1] - line[i]
    return math.atan2(d[1], d[0])


def test_pure_pursuit_labels() -> None:
    route = maps.load("driving_school").route("loop_ccw")
    line, loop = labels.lane_polyline("driving_school", "loop_ccw", 0)
    assert loop and np.allclose(line, np.asarray(route.polyline_m))
    # the longest run of equal headings: a straight; its middle point
    yaw = np.array([heading(line, i) for i in range(len(line) - 1)])
    same = np.abs(np.diff(yaw)) < 1e-6
    best, start, run = (0, 0), 0, 0
    for i, s in enumerate(same):
        run = run + 1 if s else 0
        start = i - run + 1 if s else start
        if run > best[0]:
            best = (run, i - run + 1)
    assert best[0] * 0.05 > 1.0, "no straight of 1 m on loop_ccw"
    mid = best[1] + best[0] // 2
    x, y = line[mid]
    h = yaw[mid]
    on = labels.pursuit_steering(np.array([[x, y, h]]), line, loop, 0.45)[0]
    assert abs(on) < 1e-6, on
    left = np.array([[x - 0.03 * math.sin(h), y + 0.03 * math.cos(h), h]])
    near = labels.pursuit_steering(left, line, loop, 0.2)[0]
    far = labels.pursuit_steering(left, line, loop, 0.45)[0]
    assert near < far < 0, (near, far)
    # an arc: the point of the largest heading change per metre
    k = int(np.argmax(np.abs(np.diff(np.unwrap(yaw)))))
    p0, p1, p2 = line[k], line[k + 1], line[k + 2]
    a, b, c = math.dist(p0, p1), math.dist(p1, p2), math.dist(p0, p2)
    cross = (p1[0] - p0[0]) * (p2[1] - p0[1]) - (p1[1] - p0[1]) * (p2[0] - p0[0])
    radius = a * b * c / (2.0 * abs(cross))
    v = vehicle.load()
    want = math.atan(v.number("wheelbase_m") / radius) / v.number("steer_limit_rad")
    pose = np.array([[p1[0], p1[1], heading(line, k + 1) - 0.5 * (yaw[k + 1] - yaw[k])]])
    for la in (0.1, 0.2):  # shorter than the arc: the goal is on it
        got = labels.pursuit_steering(pose, line, loop, la)[0]
        assert abs(got - math.copysign(want, cross)) < 0.03, (la, got, want, radius)
    other, _ = labels.lane_polyline("driving_school", "loop_ccw", 1)
    gap = np.hypot(*(other - line).T)
    assert np.allclose(gap, 2.0 * route.half_width_m, atol=1e-6), (gap.min(), gap.max())
    side = (line[mid + 1] - line[mid])[0] * (other[mid] - line[mid])[1] - (
        line[mid + 1] - line[mid]
    )[1] * (other[mid] - line[mid])[0]
    assert side > 0, "lane_shift 1 is not on the left"
    try:
        labels.pursuit_steering(pose, line, loop, 0.0)
    except ValueError as e:
        assert "0.0" in str(e)
    else:
        raise AssertionError("a lookahead of 0 was taken")
    print(
        f"straight 0, left 0.03 m: {near:.3f} (0.2 m) {far:.3f} (0.45 m); arc r {radius:.2f} m ok"
    )
