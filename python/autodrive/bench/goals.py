"""The one rule every `tools/bench` suite judges its goals by (autodrive.bench.goals.judge).

A goal is one figure against one bound (`at_most`, `at_least`, `equals`). A suite keeps its goals
in one table (name -> Goal, every goal of its issue, whichever parts of the suite ran) and
calls judge(figures, GOALS, seeds) once, at the end: figures then carry "goals" (name -> bool),
"goals_missing" (the goals whose figure is absent), "goals_met" (every goal met) and the seeds
the figures came from (autodrive.core.seeds.span, or seeds.unseeded for a figure no seed moves). A figure
that is absent, None, not a number (a string such as "not present", NaN) or of the wrong kind
fails its goal: a part of a suite that was skipped or crashed can never say goals_met true.
A figure inside a nested object is named by a dotted path ("normal.autonomy_pct")."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, Literal

Op = Literal["<=", ">=", "=="]


@dataclass(frozen=True)
class Goal:
    """figure <op> bound; a bool bound only with "==" (a yes/no figure)."""

    figure: str
    op: Op
    bound: float | bool

    def __str__(self) -> str:
        return f"{self.figure} {self.op} {self.bound}"


def at_most(figure: str, bound: float) -> Goal:
    return Goal(figure, "<=", bound)


def at_least(figure: str, bound: float) -> Goal:
    return Goal(figure, ">=", bound)


def equals(figure: str, bound: float | bool) -> Goal:
    return Goal(figure, "==", bound)


def figure_value(figures: Mapping[str, Any], path: str) -> Any:
    """The figure at a dotted path, or None when any part of the path is absent."""
    value: Any = figures
    for part in path.split("."):
        if not isinstance(value, Mapping) or part not in value:
            return None
        value = value[part]
    return value


def _usable(value: Any, bound: float | bool) -> bool:
    """The figure is of the bound's kind: a bool for a bool bound, else a finite number."""
    if isinstance(bound, bool):
        return isinstance(value, bool)
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def met(goal: Goal, figures: Mapping[str, Any]) -> bool | None:
    """Whether the goal is met; None when its figure is missing (which fails it)."""
    value = figure_value(figures, goal.figure)
    if not _usable(value, goal.bound):
        return None
    if goal.op == "==":
        return bool(value == goal.bound)
    if isinstance(goal.bound, bool):
        raise ValueError(f"goal '{goal}': a yes/no figure takes '==' only")
    return bool(value <= goal.bound) if goal.op == "<=" else bool(value >= goal.bound)


def judge(
    figures: dict[str, Any], goals: Mapping[str, Goal], seeds: Mapping[str, Any]
) -> dict[str, Any]:
    """Adds goals / goals_missing / goals_met and the seed range to figures (and returns them).
    An empty table is refused (a suite without goals has nothing to say goals_met about), and
    so are seeds without their range."""
    if not goals:
        raise ValueError("a bench suite's goal table is empty")
    if "seed_range" not in seeds:
        raise ValueError("a bench suite's figures must say their seed range (core.seeds)")
    figures.update(seeds)
    verdicts = {name: met(goal, figures) for name, goal in goals.items()}
    figures["goals"] = {name: bool(v) for name, v in verdicts.items()}
    figures["goals_missing"] = sorted(
        f"{name} ({goals[name].figure})" for name, v in verdicts.items() if v is None
    )
    figures["goals_met"] = all(v is True for v in verdicts.values())
    return figures
