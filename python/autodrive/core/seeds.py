"""The one place of the seed ranges (docs/reference/seeds.md): training, development and
evaluation are disjoint, so a reported figure comes from seeds nothing was tuned on.

- TRAINING: what learning draws its episodes from (MARL PPO rollouts, base + copy x 1 000 003,
  and its checkpoint validation from 500 000 000; the cloning expert's recordings).
- DEVELOPMENT: anything looked at while building or debugging: tests, demos, traced failures.
  The old MARL "held-out" block 1 000 000 000-1 000 000 199 lies here: its seeds 01, 05, 10, 12,
  13, 88, 106 and 187 were traced to write the shield's standing-car rules. HIL missions (which
  train nothing) default to DEVELOPMENT_MISSION_SEED; their seeds 1-10 of earlier sessions
  (HIL seed 1, smart-city 1-5, parking 1-10) were looked at too and are never reported again.
- EVALUATION: benches only, for figures; a seed of it that anybody traces moves to development
  for good (start the next measurement past it, and say so in docs/results)."""

from __future__ import annotations

from typing import Any

TRAINING = range(0, 1_000_000_000)
DEVELOPMENT = range(1_000_000_000, 1_500_000_000)
EVALUATION = range(1_500_000_000, 2_000_000_000)  # below 2^31: every seed type takes it
RANGES = {"training": TRAINING, "development": DEVELOPMENT, "evaluation": EVALUATION}
DEVELOPMENT_MISSION_SEED = DEVELOPMENT.start + 1  # tools/demo's default --seed
# the cloning expert's recordings (tools/pilot expert / make-model --seed S: laps on S and S + 1),
# the shipped model's; a cloning evaluation never runs on a training seed
CLONING_EXPERT_SEED = TRAINING.start + 1
# tools/bench marl's default first seed (MARL_BENCH_FIRST_SEED overrides it): a block of the
# evaluation range no earlier run used (1 500 000 000 - 1 500 000 199: runs before 2026-12-02)
MARL_BENCH_FIRST_SEED = EVALUATION.start + 1000
# tools/bench v2x's smart-city and intersection runs (V2X_BENCH_SEED overrides the default):
# a block of the evaluation range kept for it, one seed per measurement, the next after each
V2X_BENCH_SEEDS = range(EVALUATION.start + 201, EVALUATION.start + 221)
# its default: the block's next unused seed (used on 2026-12-03: 201 in the morning; 202, a
# failed run after which a scorer changed, now development; 203, the reported run)
V2X_BENCH_NEXT_SEED = V2X_BENCH_SEEDS.start + 3
# tools/bench cloning's evaluations: a block of the evaluation range kept for it; the default
# --seed is the next one no measurement used (1 500 000 501: the shipped model, 2026-12-03)
CLONING_BENCH_SEEDS = range(EVALUATION.start + 501, EVALUATION.start + 521)
CLONING_BENCH_NEXT_SEED = CLONING_BENCH_SEEDS.start + 1


def range_of(seed: int) -> str:
    """The name of the range seed lies in; ValueError for a seed outside every range."""
    for name, r in RANGES.items():
        if seed in r:
            return name
    raise ValueError(f"seed {seed} lies outside every seed range (autodrive.core.seeds)")


def require(seed: int, allowed: tuple[str, ...], what: str) -> int:
    """seed when it lies in one of the allowed ranges; ValueError naming what it is for and its
    range otherwise (a cloning evaluation on a training seed, a recording on an evaluation one)."""
    name = range_of(seed)
    if name not in allowed:
        raise ValueError(
            f"{what} {seed} is a {name} seed; it must be a {' or '.join(allowed)} seed "
            "(autodrive.core.seeds, docs/reference/seeds.md)"
        )
    return seed


def span(first: int, count: int) -> dict[str, Any]:
    """What a bench records in its JSON: its seeds first .. first + count - 1 and their range
    (ValueError when they straddle two ranges)."""
    if count < 1:
        raise ValueError(f"seed span of {count} seeds")
    name = range_of(first)
    if range_of(first + count - 1) != name:
        raise ValueError(f"seeds {first}..{first + count - 1} straddle two seed ranges")
    return {"seed_range": name, "first_seed": first, "seeds": count}


def unseeded(why: str) -> dict[str, Any]:
    """What a bench without seeded episodes records instead (a throughput or latency figure,
    the same whatever the seed): why."""
    return {"seed_range": "none", "seed_note": why}
