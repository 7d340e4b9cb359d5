"""Unit checks of autodrive' pure parts: the one angle wrap, frame changes and their
inverse, the alignment of a dead-reckoned track, clearances, the map facts and the slot goal,
the runtime config the demo writes, and bad input named in the error."""

import math
from pathlib import Path

from pyhelpers import raises

from autodrive.core import geometry
from autodrive.maps import facts as mapfacts
from autodrive.hil import scoring
from autodrive.core import vehicle
from autodrive.hil.city import scoring as city_scoring
from autodrive.maps.loader import MAPS_DIR
from autodrive.hil.missions import parking
from autodrive.core.runfiles import read_columns


def test_angle_wrap() -> None:
    for a in (-7.0, -math.pi, 0.0, 3.0, math.pi, 9.5):
        w = geometry.wrap(a)
        assert abs(w) <= math.pi and abs(math.remainder(w - a, 2 * math.pi)) < 1e-12, (a, w)


def test_frame_change_round_trips() -> None:
    origin, p = (0.5, -1.2, 2.0), (1.0, 2.0, -2.5)
    back = geometry.to_world(origin, geometry.to_frame(origin, p))
    assert all(abs(x - y) < 1e-12 for x, y in zip(back, p)), back


def test_alignment_of_dead_reckoned_track() -> None:
    align = geometry.Alignment((1.0, 1.0, 0.0), (0.0, 0.0, math.pi / 2))
    x, y = align.point(2.0, 1.0)  # 1 m ahead of the estimate's start: 1 m along the truth's +y
    assert abs(x) < 1e-12 and abs(y - 1.0) < 1e-12, (x, y)


def test_clearances() -> None:
    car = vehicle.load()
    square = geometry.rect_corners((0.0, 0.0, 0.5, 0.5, 0.0))
    far = geometry.rect_corners((2.0, 0.0, 0.5, 0.5, 0.0))
    assert abs(geometry.polygon_distance(square, far) - 1.0) < 1e-12
    env = car.envelope
    assert env.length_m == car.vector("chassis_size_m")[0]
    assert env.width_m >= car.number("track_m") + car.number("wheel_width_m")
    clear = scoring.min_clearance([(0.0, 0.0, 0.0)], car, [(1.0, 0.0, 0.1, 0.1, 0.0)], stride=1)
    expect = 1.0 - 0.1 - (env.centre_ahead_m + env.length_m / 2)
    assert abs(clear - expect) < 1e-9, (clear, expect)
    assert scoring.rms([3.0, 4.0]) == math.sqrt(12.5)


def test_map_facts_and_slot_goal() -> None:
    env = vehicle.load().envelope
    lot = mapfacts.parking_school()
    assert lot.obstacles and lot.slots > 0
    assert parking.start_pose(None, 0) == lot.spawn, "seed 0 starts exactly at the spawn"
    s1 = parking.start_pose(None, 1)
    assert s1 == parking.start_pose(None, 1) and s1 != lot.spawn, "a seed draws one start"
    goal = parking.slot_goal_world(2)
    # The envelope's centre, not the rear axle, is in the slot's centre.
    centre = env.at(goal)
    slot_x, slot_y, slot_yaw = lot.slot_centres[2]
    assert abs(centre[0] - slot_x) < 1e-9 and abs(centre[1] - slot_y) < 1e-9, (
        centre,
        lot.slot_centres,
    )
    assert abs(centre[4] - slot_yaw) < 1e-12
    raises(lambda: parking.slot_goal_world(lot.slots), RuntimeError, "slots 0..")
    raises(lambda: parking.mapping_route("1,2"), ValueError, "leg '1,2'")


def test_bad_columns_named_in_error(tmp_path: Path) -> None:
    csv = tmp_path / "t.csv"
    csv.write_text("x_m,y_m\n1,2\n3,x\n")
    raises(lambda: read_columns(csv, ["x_m", "y_m"]), ValueError, str(csv), "non-numeric")
    raises(lambda: read_columns(csv, ["z_m"]), ValueError, "lacks columns")


def test_city_scorer_blocked_cars() -> None:
    # the smart-city scorer: a car standing away from every stop line for blocked_s is blocked; one
    # standing at a stop line, or moving, is not
    town = city_scoring.MapFacts.load(MAPS_DIR / "tiny_town.json")
    sc = city_scoring.Scorer(town, blocked_s=30.0)
    for k in range(400):  # 40 s standing in the middle of the east road
        sc.truth("NIGEL1", k * 0.1, 4.06, 0.5, -math.pi / 2, False)
        sc.truth("NIGEL2", k * 0.1, 4.34, 0.5 + k * 0.01, math.pi / 2, False)
    rep = sc.report()
    assert rep["blocked"] == ["NIGEL1"], rep
    assert rep["longest_standstill_away_s"] == {"NIGEL1": 39.9, "NIGEL2": 0.0}, rep
    print("python tools ok")
