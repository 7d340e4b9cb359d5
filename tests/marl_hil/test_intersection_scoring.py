"""The intersection mission's scoring (missions/intersection.py) is shown to catch what it scores,
on constructed episodes (no simulator): a car whose EKF says "at the goal" while its ground truth
is off is no success; episodes a wall --timeout left unrun count as failures in the rate; and
the mean traverse time counts the cars that did not arrive (at the episode's whole length); and
the mission's exit code fails a collision, a run a wall --timeout shortened, and a sanitizer
report."""

import pytest

from autodrive.hil.missions import intersection as mission
from autodrive.hil.missions.intersection import CarPlan, EpisodeRecord


def episode(true_offsets_m: list[float]) -> tuple[list[CarPlan], EpisodeRecord]:
    """Four cars whose EKFs all said "at the goal" at t = 20 s, each truly off its goal by its
    offset then."""
    plans, rec = [], EpisodeRecord()
    for i, off in enumerate(true_offsets_m):
        v = f"nigel{i + 1}"
        goal = (float(i), 2.0)
        plans.append(CarPlan(v, "r", (0.0, 0.0, 0.0), goal))
        rec.truth[v] = [(19.9, goal[0] + 1.0, goal[1]), (20.0, goal[0] + off, goal[1])]
        rec.at_goal.add(v)
        rec.goal_t[v] = 20.0
    return plans, rec


def test_success_is_judged_from_ground_truth() -> None:
    plans, rec = episode([0.02, 0.05, 0.1, 0.0])
    assert mission.episode_outcome(plans, rec, "goal") == "goal"
    plans, rec = episode([0.02, 0.05, mission.GOAL_TRUE_TOLERANCE_M + 0.1, 0.0])
    assert mission.episode_outcome(plans, rec, "goal") == "goal_false"
    plans, rec = episode([0.0] * 4)
    rec.at_goal.discard("nigel4")  # its EKF never said so: not at the goal either
    assert mission.episode_outcome(plans, rec, "goal") == "goal_false"
    plans, rec = episode([0.0] * 4)
    del rec.truth["nigel2"]
    assert mission.episode_outcome(plans, rec, "goal") == "goal_false"
    assert mission.episode_outcome(plans, rec, "timeout") == "timeout"


def test_unrun_episodes_are_failures() -> None:
    arrived = [[10.0, 12.0, 14.0, 16.0]]
    s = mission.score_episodes(5, ["goal"], arrived)  # a wall --timeout after 1 of 5
    assert s["success_rate"] == pytest.approx(0.2) and s["episodes_not_run"] == 4
    s = mission.score_episodes(1, ["goal"], arrived)
    assert s["success_rate"] == 1.0 and s["mean_traverse_s"] == pytest.approx(13.0)
    s = mission.score_episodes(2, ["goal", "goal_false"], arrived * 2)
    assert s["success_rate"] == 0.5 and s["goal_believed_not_true"] == 1


def test_mean_traverse_counts_the_cars_that_did_not_arrive() -> None:
    s = mission.score_episodes(1, ["timeout"], [[10.0, 10.0, None, None]])
    assert s["mean_traverse_s_arrived"] == pytest.approx(10.0)
    assert s["mean_traverse_s"] == pytest.approx((20.0 + 2 * mission.EPISODE_SIM_S) / 4)
    assert s["cars_arrived"] == 2 and s["timeouts"] == 1 and s["success_rate"] == 0.0


def report(requested: int, outcomes: list[str], collisions: int = 0) -> dict[str, object]:
    """The parts of a mission report its verdict reads, for run episodes' outcomes."""
    arrived = [[10.0, 12.0, 14.0, 16.0] if o == "goal" else [None] * 4 for o in outcomes]
    rep = dict(mission.score_episodes(requested, outcomes, arrived))
    rep.update(collisions=collisions, sanitizer_reports=[])
    return rep


def test_a_collision_fails_the_mission() -> None:
    plans, rec = episode([0.0] * 4)
    rec.collided.add("nigel2")
    outcome = mission.episode_outcome(plans, rec, "collision")
    assert outcome == "collision"
    rep = report(2, ["goal", outcome], collisions=1)
    assert rep["success_rate"] == 0.5 and mission.exit_code(rep) == 1
    assert mission.exit_code(report(2, ["goal", "goal"])) == 0


def test_a_wall_timeout_that_shortens_the_run_fails_it() -> None:
    assert mission.exit_code(report(20, ["goal"] * 19)) == 1  # 19 of 20 planned, all good
    assert mission.exit_code(report(2, ["goal", "timeout"])) == 1
    rep = report(2, ["goal", "goal"])
    rep["sanitizer_reports"] = ["autodrive-marl nigel1: LeakSanitizer"]
    assert mission.exit_code(rep) == 1
