"""The learning API's world: reset with the same seed gives the same episode (bit for bit, two
cars, LIDAR), the batch step equals single steps, commands reach the wheels only through the
firmware (armed after 60 ms), the lane flag, and bad inputs are refused with a clear message."""

import math

import numpy as np

from autodrive.gym import SimError, World
from autodrive.gym import step_worlds
from autodrive.gym import tasks

PERIOD_MS = 50  # 20 Hz control


def episode(w: World, seed: int, steps: int = 40) -> np.ndarray:
    w.reset(seed)
    rows = []
    for k in range(steps):
        for car in range(w.cars):
            w.command(car, 0.4 + 0.3 * math.sin(0.2 * k + car), 0.8 * math.cos(0.15 * k))
        w.step(PERIOD_MS)
        for car in range(w.cars):
            o = w.observe(car)
            rows.append(
                np.concatenate(
                    [
                        o.pos_m,
                        o.quat_wxyz,
                        o.vel_body_m_s,
                        o.wheel_speed_rad_s,
                        o.imu_gyro_rad_s,
                        o.imu_accel_m_s2,
                        w.lidar(car).astype(np.float64),
                    ]
                )
            )
    return np.asarray(rows)


def test_repeatable() -> None:
    w = World("parking_school", cars=2, seed=0, lidar_rays=90)
    a, b, c = episode(w, 5), episode(w, 5), episode(w, 6)
    assert np.array_equal(a, b), "the same seed gave a different episode"
    assert not np.array_equal(a, c), "another seed gave the same IMU biases"
    fresh = World("parking_school", cars=2, seed=5, lidar_rays=90)
    assert np.array_equal(episode(fresh, 5), a), "a fresh world differs from a reset one"
    moved = np.hypot(*(a[-2, :2] - a[0, :2]))
    assert moved > 0.1, f"car 1 moved only {moved:.3f} m"
    print(f"repeatable: 2 cars x 40 steps identical; car 1 moved {moved:.2f} m")


def test_batch_equals_single() -> None:
    seeds = (1, 2, 3, 4)
    single = [World("parking_school", seed=s) for s in seeds]
    batch = [World("parking_school", seed=s) for s in seeds]
    threaded = [World("parking_school", seed=s) for s in seeds]
    for ws in (single, batch, threaded):
        for i, w in enumerate(ws):
            w.command(0, 0.3 + 0.2 * i, -0.5 + 0.3 * i)
    for _ in range(20):
        for w in single:
            w.step(PERIOD_MS)
        step_worlds(batch, PERIOD_MS)
        step_worlds(threaded, PERIOD_MS, threads=3)
    for s, b, t in zip(single, batch, threaded):
        assert np.array_equal(s.observe(0).pos_m, b.observe(0).pos_m)
        assert np.array_equal(s.observe(0).pos_m, t.observe(0).pos_m)
        assert s.time_s == b.time_s == t.time_s == 1.0
    try:
        step_worlds(batch, 0, threads=2)
        raise AssertionError("a bad period was not refused")
    except SimError as e:
        assert "world 0" in str(e) and "period 0" in str(e), str(e)
    print("batch step, also on 3 threads, equals single steps")


def test_firmware_path() -> None:
    w = World("parking_school", seed=1)
    w.command(0, 1.0, 0.0)
    w.step(40)  # two engaged=0 frames (0, 20 ms) so far: the Nano is not engaged yet
    o = w.observe(0)
    assert not o.nano_engaged and abs(o.wheel_speed_rad_s[2]) < 0.5, o
    w.step(460)
    o = w.observe(0)
    assert o.nano_engaged and o.vel_body_m_s[0] > 0.05, o
    # the firmware's throttle slew: the wheels do not reach speed in one 20 ms frame
    w.reset(1)
    w.command(0, 1.0, 0.0)
    w.step(80)
    v80 = w.observe(0).wheel_speed_rad_s[2]
    w.step(420)
    assert v80 < 0.5 * w.observe(0).wheel_speed_rad_s[2], "no slew limit on the throttle"
    print("commands go through the firmware: armed after 60 ms, slewed")


def test_lane_flag() -> None:
    r = tasks.route("driving_school", "loop_ccw")
    w = World("driving_school", seed=1)
    w.set_route_points(0, r.points_m, r.half_width_m, r.loop)
    w.reset(1, [r.pose_at(0)])
    o = w.observe(0)
    assert o.has_route and not o.off_lane and abs(o.route_lateral_m) < 1e-6, o
    w.command(0, 0.6, 1.0)  # full left lock: off the lane to the left within a few seconds
    left = None
    for k in range(100):
        w.step(PERIOD_MS)
        o = w.observe(0)
        if o.off_lane:
            left = k
            break
    assert left is not None and o.route_lateral_m > r.half_width_m, o
    w.set_route(0, None)
    plain = World("parking_school", seed=1)
    assert not plain.observe(0).off_lane  # no lanes on the map: never off lane
    if tasks.map_exists(tasks.INTERSECTION_MAP):  # no route: off every lane_* numeric's width
        x = World(tasks.INTERSECTION_MAP, seed=1)
        spawn = tasks.sidecar(tasks.INTERSECTION_MAP)["spawns"][0]
        x.reset(1, [(spawn["x_m"], spawn["y_m"], spawn["yaw_rad"])])
        assert not x.observe(0).off_lane, "a car at a spawn on its lane is off lane"
        x.reset(1, [(2.0, 2.0, 0.0)])  # a corner block of the crossroads, off every lane
        assert x.observe(0).off_lane, "a car off every lane is not flagged"
    print(f"lane flag: off lane to the left after {left + 1} control periods")


def test_camera() -> None:
    w = World("parking_school", seed=1, camera_px=(64, 48))
    img = w.camera(0)
    assert img.shape == (48, 64, 3) and img.dtype == np.uint8
    assert img.std() > 5.0, "the front camera rendered a blank frame"
    print(f"front camera: 64 x 48 RGB, mean {img.mean():.1f}, std {img.std():.1f}")


def refused(fn: object, words: str) -> None:
    try:
        fn()  # type: ignore[operator]
    except SimError as e:
        assert words in str(e), f"message '{e}' lacks '{words}'"
        return
    raise AssertionError(f"not refused (expected '{words}')")


def test_bad_input() -> None:
    refused(lambda: World("no_such_map"), "no_such_map")
    refused(lambda: World("parking_school", cars=0), "--cars 0")
    w = World("parking_school", lidar_rays=36)
    refused(lambda: w.command(3, 0.0, 0.0), "car 3")
    refused(lambda: w.command(0, 1.5, 0.0), "throttle 1.5")
    refused(lambda: w.step(0), "period 0")
    refused(lambda: w.set_route(0, "nowhere"), "route 'nowhere'")
    refused(lambda: w.reset(1, [(1.5, 0.0, 0.0)]), "reset pose of car 0")  # on box_a
    refused(lambda: w.reset(1, [(float("nan"), 0.0, 0.0)]), "not a finite pose")
    w.reset(1)  # the world still works after the refusals
    w.step(10)
    print("bad inputs refused with messages naming them")
