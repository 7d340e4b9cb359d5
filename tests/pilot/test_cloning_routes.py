"""The cloning mission's conditions and their routes (missions/cloning.py, lane_watch.py), from
the map's own data, no simulator: `reverse` is the recorded route's centre line driven the other
way (the same points, in reverse order) from the normal start turned round, and its referee
follows that same lane: laps count up in the direction driven, offsets are + to the driver's
left, a wheel over the bound is out, a reset faces the direction driven; driving the normal
route's way counts no reversed laps. `other-lane` is the road's other lane (loop_cw), one lane
width from the recorded one; each of the issue's three unseen conditions is run by the bench."""

from __future__ import annotations

import math

import numpy as np

from autodrive.bench import cloning as bench
from autodrive.hil.missions import cloning, lane_watch
from autodrive.learn.pilot.expert import ExpertRun


def angle_diff(a: float, b: float) -> float:
    return abs((a - b + math.pi) % (2 * math.pi) - math.pi)


def drive(watch: lane_watch.LaneWatch, pts: list[tuple[float, float]], start: int) -> None:
    """Feeds the watch the poses of a car on pts from index start, once round, in pts' order."""
    n = len(pts) - 1  # a loop repeats its first point last
    for k in range(n + 1):
        (x0, y0), (x1, y1) = pts[(start + k) % n], pts[(start + k + 1) % n]
        watch.update((x0, y0, math.atan2(y1 - y0, x1 - x0)))


def test_cloning_routes_from_map() -> None:
    normal, n_start = cloning.condition_route("normal")
    rev, r_start = cloning.condition_route("reverse")
    # the recorded route is the normal one; reverse drives its very points the other way
    assert normal.name == ExpertRun.route, normal.name
    assert rev.name == f"{normal.name}:reversed" and rev.loop, rev.name
    assert rev.polyline_m == normal.polyline_m[::-1]
    assert rev.half_width_m == normal.half_width_m
    assert math.isclose(rev.length_m, normal.length_m, rel_tol=1e-12)
    # the start: the normal one's point, facing the other way, on the line and along it
    assert math.dist((r_start.x_m, r_start.y_m), (n_start.x_m, n_start.y_m)) < 1e-9
    assert angle_diff(r_start.yaw_rad, n_start.yaw_rad + math.pi) < 1e-9
    watch = lane_watch.for_route(rev)
    off, _, on_line = watch.locate(r_start.x_m, r_start.y_m)
    assert abs(off) < 1e-9 and angle_diff(on_line[2], r_start.yaw_rad) < 1e-9, (off, on_line)
    assert not watch.wheels_out((r_start.x_m, r_start.y_m, r_start.yaw_rad))
    # + is the driver's left: on the reversed lane the normal route's right
    left = r_start.yaw_rad + math.pi / 2
    d = 0.5 * rev.half_width_m
    p = (r_start.x_m + d * math.cos(left), r_start.y_m + d * math.sin(left))
    assert math.isclose(watch.locate(*p)[0], d, abs_tol=1e-9)
    assert math.isclose(lane_watch.for_route(normal).locate(*p)[0], -d, abs_tol=1e-9)
    # a car half a lane plus its wheel track to the left has wheels over the bound
    far = rev.half_width_m + 0.5 * max(abs(w[1]) for w in watch.wheel_points_m)
    out = (r_start.x_m + far * math.cos(left), r_start.y_m + far * math.sin(left))
    assert watch.wheels_out((*out, r_start.yaw_rad))
    # laps: one lap round the reversed lane from the start counts +1 on its watch...
    i0 = int(np.argmin([math.dist(q, (r_start.x_m, r_start.y_m)) for q in rev.polyline_m[:-1]]))
    drive(watch, rev.polyline_m, i0)
    assert math.isclose(watch.laps, 1.0, abs_tol=0.01), watch.laps
    # ...and driving the recorded direction counts -1 there, +1 on the recorded route's watch
    wrong, right = lane_watch.for_route(rev), lane_watch.for_route(normal)
    j0 = int(np.argmin([math.dist(q, (n_start.x_m, n_start.y_m)) for q in normal.polyline_m[:-1]]))
    drive(wrong, normal.polyline_m, j0)
    drive(right, normal.polyline_m, j0)
    assert math.isclose(wrong.laps, -1.0, abs_tol=0.01), wrong.laps
    assert math.isclose(right.laps, 1.0, abs_tol=0.01), right.laps
    # a reset (the nearest centre-line pose) faces the direction driven
    _, _, back = watch.locate(p[0], p[1])
    assert angle_diff(back[2], r_start.yaw_rad) < 1e-9, back
    # other-lane: the road's other lane, not the recorded one reversed: a lane width away
    other, o_start = cloning.condition_route("other-lane")
    assert other.name != normal.name and not other.name.endswith(":reversed")
    gap = abs(lane_watch.for_route(normal).locate(o_start.x_m, o_start.y_m)[0])
    assert math.isclose(gap, 2 * normal.half_width_m, abs_tol=1e-6), gap
    # the bench runs the three unseen conditions, and other-lane besides
    assert set(bench.UNSEEN) == {"night", "noise2x", "reverse"}, bench.UNSEEN
    assert "other-lane" in bench.EXTRA and set(bench.UNSEEN + bench.EXTRA) <= set(cloning.ROUTES)
    for c in ("night", "noise2x"):
        assert cloning.condition_route(c)[0].polyline_m == normal.polyline_m, c
    # the report's route name and the parser know every condition
    for c in cloning.CONDITIONS:
        assert cloning.parse_args(["--condition", c]).condition == c
    print(f"reverse: {rev.name}, {rev.length_m:.2f} m, start ({r_start.x_m:+.3f}, "
          f"{r_start.y_m:+.3f}, {math.degrees(r_start.yaw_rad):+.1f} deg); other-lane: "
          f"{other.name}, {gap:.3f} m from the recorded lane")  # fmt: skip
