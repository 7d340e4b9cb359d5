"""The Python binding of the one pure pursuit (autodrive.core.pure_pursuit, cffi on
libautodrive_path_tracking.so) gives the C library's answers."""

from __future__ import annotations

import math

from autodrive.core import pure_pursuit, vehicle


def test_default_vehicle_is_the_vehicle_description() -> None:
    car = vehicle.load()
    v = pure_pursuit.default_vehicle()
    assert math.isclose(v.wheelbase_m, car.number("wheelbase_m"))
    assert math.isclose(v.steer_limit_rad, car.number("steer_limit_rad"))


def test_steer_to_is_atan_of_two_lateral_over_distance_squared() -> None:
    v = pure_pursuit.Vehicle(0.15, 0.5)
    assert math.isclose(pure_pursuit.steer_to((0.0, 0.0, 0.0), (0.3, 0.1), v), math.atan(0.3))
    assert math.isclose(pure_pursuit.steer_to((0.0, 0.0, 0.0), (0.3, -0.1), v), -math.atan(0.3))
    assert pure_pursuit.steer_to((0.0, 0.0, 0.0), (0.0, 0.1), v) == 0.5  # clamped
    # the car's frame: rotated by 90 deg, the same goal relative to it
    rotated = pure_pursuit.steer_to((1.0, 1.0, math.pi / 2), (0.9, 1.3), v)
    assert math.isclose(rotated, math.atan(0.3))


def test_goal_index_is_the_first_sample_the_lookahead_away() -> None:
    line = pure_pursuit.Polyline([(0.1 * i, 0.0) for i in range(5)])
    assert line.n == 5
    assert line.goal_index(0, 0.0, 0.0, 0.25) == 3
    assert line.goal_index(0, 0.0, 0.0, 0.2) == 2
    assert line.goal_index(4, 0.0, 0.0, 0.1) == 4
    assert line.goal_index(0, 0.0, 0.0, 1.0) == 5


def test_path_steers_a_circle_as_the_circle_itself() -> None:
    r_m, n = 0.6, 188
    circle = [
        (r_m * math.cos(2 * math.pi * i / n), r_m * math.sin(2 * math.pi * i / n)) for i in range(n)
    ]
    path = pure_pursuit.PathTracker(circle, loop=True)
    assert math.isclose(path.length_m, 2 * math.pi * r_m, rel_tol=1e-3)
    wheelbase = pure_pursuit.default_vehicle().wheelbase_m
    for lookahead_m in (0.1, 0.2, 0.4):
        got = path.steer_nearest((r_m, 0.0, math.pi / 2), lookahead_m)
        assert abs(got - math.atan(wheelbase / r_m)) < 2e-3, lookahead_m


def test_path_refuses_a_single_point() -> None:
    try:
        pure_pursuit.PathTracker([(0.0, 0.0)], loop=False)
    except ValueError as e:
        assert "2 points" in str(e)
    else:
        raise AssertionError("a one-point path was accepted")
