"""The smart-city scorer (autodrive.hil.city.scoring) is shown to catch what it scores: constructed
ground-truth runs with planted faults (a red-light run, a stop-sign roll, a stop past the line,
a collision) on a straight lane along +x with a light's stop line at x = 0 and a stop sign's at
x = 5 m; each fault must be counted, and the clean runs beside them must count nothing."""

import math
from pathlib import Path

import lcm
import pytest

from autodrive.core import lcmtypes
from autodrive.core.channels import channel
from autodrive.hil.city.rescore import rescore

from autodrive.hil.city.scoring import RED, MapFacts, Scorer, StopPoint, front_offset_m

GREEN = 3
LIGHT = 7
STEP_S = 0.02  # ground truth at 50 Hz [s]


def facts():
    lane = [{"x_m": x * 0.5 - 5.0, "y_m": 0.0, "heading_rad": 0.0} for x in range(31)]
    stops = [
        StopPoint("light_line", 0.0, 0.0, 0.0, LIGHT),
        StopPoint("sign_line", 5.0, 0.0, 0.0, -1),
    ]
    return MapFacts({"east": lane}, stops)


class Drive:
    """One car along y = 0, its front (not its rear axle) placed at x by the caller."""

    def __init__(self, scorer, car="car1"):
        self.s, self.car, self.t = scorer, car, 0.0
        self.front = front_offset_m()

    def at(self, front_x, hit=False, y=0.0):
        self.s.truth(self.car, self.t, front_x - self.front, y, 0.0, hit)
        self.t += STEP_S

    def drive(self, from_x, to_x, v):
        n = max(1, int(abs(to_x - from_x) / (v * STEP_S)))
        for k in range(n + 1):
            self.at(from_x + (to_x - from_x) * k / n)

    def stand(self, front_x, seconds):
        for _ in range(int(seconds / STEP_S)):
            self.at(front_x)


def scorer(light_state):
    s = Scorer(facts())
    s.light(LIGHT, light_state)
    return s


def test_a_red_light_run_is_counted():
    s = scorer(RED)
    Drive(s).drive(-1.0, 1.0, 0.2)
    r = s.report()
    assert r["red_light_violations"] == 1
    assert r["violations"][0]["stop"] == "light_line"


def test_crossing_on_green_and_after_standing_at_red_is_not_a_violation():
    s = scorer(GREEN)
    Drive(s).drive(-1.0, 1.0, 0.2)
    assert s.report()["red_light_violations"] == 0
    s = scorer(RED)
    d = Drive(s)
    d.drive(-1.0, -0.05, 0.2)
    d.stand(-0.05, 2.0)
    s.light(LIGHT, GREEN)
    d.drive(-0.05, 1.0, 0.2)
    r = s.report()
    assert r["red_light_violations"] == 0 and r["stop_line_crossings"]["after_red_stop"] == 1


def test_a_rolled_stop_sign_is_counted():
    s = scorer(GREEN)
    d = Drive(s)
    d.drive(4.0, 4.9, 0.2)
    d.drive(4.9, 5.5, 0.05)  # slows, never stands
    r = s.report()
    assert r["stop_sign_violations"] == 1
    assert r["violations"][0]["stop"] == "sign_line"


def test_a_short_stop_at_a_stop_sign_is_counted_and_a_full_one_is_not():
    for hold_s, violations in ((0.4, 1), (1.5, 0)):
        s = scorer(GREEN)
        d = Drive(s)
        d.drive(4.0, 4.95, 0.2)
        d.stand(4.95, hold_s)
        d.drive(4.95, 5.5, 0.2)
        assert s.report()["stop_sign_violations"] == violations, hold_s


def test_a_stop_past_the_line_is_measured_as_overshoot():
    s = scorer(RED)
    d = Drive(s)
    d.drive(-1.0, 0.12, 0.2)  # crosses at red (a violation too) and stands 12 cm past
    d.stand(0.12, 2.0)
    r = s.report()
    assert math.isclose(r["max_stop_line_overshoot_m"], 0.12, abs_tol=0.005)
    assert r["max_stop_line_overshoot_at"]["stop"] == "light_line"
    s = scorer(RED)
    d = Drive(s)
    d.drive(-1.0, -0.05, 0.2)
    d.stand(-0.05, 2.0)
    assert s.report()["max_stop_line_overshoot_m"] == 0.0


def test_a_repeated_sample_while_pulling_away_is_no_overshoot():
    # A full stop at the sign, then off at 0.2 m/s; one ground-truth sample arrives twice 0.28 m
    # past the line. That is no standstill past the line.
    s = scorer(GREEN)
    d = Drive(s)
    d.drive(4.0, 4.95, 0.2)
    d.stand(4.95, 1.5)
    d.drive(4.95, 5.28, 0.2)
    d.at(5.28)
    d.drive(5.28, 5.6, 0.2)
    r = s.report()
    assert r["max_stop_line_overshoot_m"] == 0.0 and r["stop_sign_violations"] == 0
    # the planted fault beside it: a real stop 0.28 m past the sign's line is measured
    s = scorer(GREEN)
    d = Drive(s)
    d.drive(4.0, 5.28, 0.2)
    d.stand(5.28, 1.0)
    assert math.isclose(s.report()["max_stop_line_overshoot_m"], 0.28, abs_tol=0.005)


def test_a_collision_is_counted_once_per_contact():
    s = scorer(GREEN)
    d = Drive(s)
    d.at(-2.0)
    d.at(-1.99, hit=True)
    d.at(-1.98, hit=True)
    d.at(-1.97)
    d.at(-1.96, hit=True)
    assert s.report()["collisions"] == 2


def test_a_recorded_red_light_run_is_scored_again_from_its_log(build_dir: Path, tmp_path: Path):
    # The same planted red-light run, written to an LCM log as the simulator would publish it.
    types = lcmtypes.load(build_dir)
    log = tmp_path / "run.lcmlog"
    writer = lcm.EventLog(str(log), "w", overwrite=True)
    light = types.traffic_light_state_t()
    light.light_id, light.state = LIGHT, RED
    writer.write_event(0, "TRAFFIC_LIGHT_STATE", light.encode())
    front = front_offset_m()
    for k in range(101):
        m = types.ground_truth_t()
        m.utime, m.vehicle = int(k * STEP_S * 1e6), "car1"
        m.position_m = [-1.0 + 0.02 * k - front, 0.0, 0.0]
        writer.write_event(m.utime, channel("GROUND_TRUTH", "car1"), m.encode())
    writer.close()
    r = rescore(log, facts(), build_dir)
    assert r["red_light_violations"] == 1 and r["violations"][0]["stop"] == "light_line"
    empty = tmp_path / "empty.lcmlog"
    lcm.EventLog(str(empty), "w", overwrite=True).close()
    with pytest.raises(ValueError, match="no <VEH>_GROUND_TRUTH"):
        rescore(empty, facts(), build_dir)


def test_a_car_standing_in_its_nanos_failsafe_is_named_so():
    from autodrive.hil.missions.smart_city import why_blocked

    assert "latched failsafe" in why_blocked(["NIGEL2"], {"NIGEL2": 2, "NIGEL1": 1})
    assert why_blocked(["NIGEL2"], {"NIGEL2": 1}) == "an obstacle on the lane"
