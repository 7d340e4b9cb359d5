"""Every tools/bench suite judges its goals by the one rule (autodrive.bench.goals.judge): each
suite's goal table, fed figures that meet every goal, says goals_met true; with any one figure
missing (absent, None, a string) it says false and names the goal. No suite is run: only its
goal evaluation, on constructed figures."""

import importlib
import pathlib

import pytest

from autodrive.bench import SUITES
from autodrive.bench import goals as bench_goals
from autodrive.core import seeds

BENCH_DIR = pathlib.Path(bench_goals.__file__).parent
SEEDS = seeds.unseeded("constructed figures")


def judge(figures, goals):
    return bench_goals.judge(figures, goals, SEEDS)


def table(suite):
    mod = importlib.import_module(f"autodrive.bench.{suite}")
    if hasattr(mod, "goal_table"):
        return mod.goal_table()
    return mod.GOALS


def put(figures, path, value):
    *parents, last = path.split(".")
    for p in parents:
        figures = figures.setdefault(p, {})
    figures[last] = value


def drop(figures, path):
    *parents, last = path.split(".")
    for p in parents:
        figures = figures[p]
    del figures[last]


def meeting(goals):
    """Figures that meet every goal: each at its bound."""
    figures = {}
    for g in goals.values():
        put(figures, g.figure, g.bound)
    return figures


@pytest.mark.parametrize("suite", SUITES)
def test_every_suite_has_goals_and_judges_them_by_the_one_rule(suite):
    goals = table(suite)
    assert goals, f"{suite}: no goals"
    assert judge(meeting(goals), goals)["goals_met"] is True
    source = (BENCH_DIR / f"{suite}.py").read_text()
    via_sweep = "sweep.GOALS" in source  # parking: judged in the sweep's aggregate
    assert via_sweep or "judge(" in source, f"{suite}.py never calls goals.judge"


@pytest.mark.parametrize("suite", SUITES)
def test_a_missing_figure_fails_its_goal_in_every_suite(suite):
    goals = table(suite)
    for name, goal in goals.items():
        for missing in (None, "not present", "absent"):
            figures = meeting(goals)
            if missing == "absent":
                drop(figures, goal.figure)
            else:
                put(figures, goal.figure, missing)
            res = judge(figures, goals)
            assert res["goals_met"] is False, f"{suite}: {name} with its figure {missing}"
            assert res["goals"][name] is False
            assert any(m.startswith(f"{name} (") for m in res["goals_missing"]), res


def test_security_skip_demo_cannot_meet_goals():
    """--skip-demo measures only the flood: the demo's goals (wrong key included) fail."""
    goals = table("security")
    assert "wrong_key_cmd_applied" in goals
    flood_only = {"serial_cmd_rate_ratio": 0.98, "serial_cmd_hz_configured": 50.0}
    res = judge(flood_only, goals)
    assert res["goals_met"] is False
    assert res["goals"]["serial_cmd_rate_under_flood"] is True
    assert not res["goals"]["wrong_key_cmd_applied"]


def test_a_wrong_key_command_applied_fails_security():
    goals = table("security")
    figures = meeting(goals)
    figures["wrong_key_cmd_applied"] = 1
    assert judge(figures, goals)["goals_met"] is False


def test_bounds_and_kinds():
    goals = {
        "low": bench_goals.at_most("a", 1.0),
        "high": bench_goals.at_least("b.c", 2),
        "yes": bench_goals.equals("d", True),
    }
    ok = {"a": 1.0, "b": {"c": 2.5}, "d": True}
    assert judge(dict(ok), goals)["goals_met"] is True
    for bad in ({"a": 1.01}, {"b": {"c": 1.9}}, {"d": False}, {"d": 1}, {"a": float("nan")},
                {"a": True}, {"b": 3}):  # fmt: skip
        res = judge({**ok, **bad}, goals)
        assert res["goals_met"] is False, bad
    with pytest.raises(ValueError, match="empty"):
        judge({}, {})
    with pytest.raises(ValueError, match="seed range"):
        bench_goals.judge({}, goals, {})
    assert judge(dict(ok), goals)["seed_range"] == "none"


def test_seed_ranges_are_disjoint_and_spans_name_theirs():
    ranges = sorted(seeds.RANGES.values(), key=lambda r: r.start)
    assert all(a.stop <= b.start for a, b in zip(ranges, ranges[1:]))
    assert max(r.stop for r in ranges) <= 2**31  # every seed type takes them
    assert seeds.range_of(seeds.DEVELOPMENT_MISSION_SEED) == "development"
    # the MARL seeds traced for the shield's rules are development, not evaluation
    for traced in (1, 5, 10, 12, 13, 88, 106, 187):
        assert seeds.range_of(1_000_000_000 + traced) == "development"
    assert seeds.span(seeds.EVALUATION.start, 200) == {
        "seed_range": "evaluation", "first_seed": seeds.EVALUATION.start, "seeds": 200}  # fmt: skip
    with pytest.raises(ValueError, match="straddle"):
        seeds.span(seeds.EVALUATION.start - 1, 2)
    with pytest.raises(ValueError, match="outside"):
        seeds.range_of(-1)


@pytest.mark.parametrize("suite", SUITES)
def test_every_suite_records_its_seeds(suite):
    source = (BENCH_DIR / f"{suite}.py").read_text()
    assert "seed_ranges." in source or "seeds." in source, f"{suite}.py names no seed range"
