"""Seeded held-out episodes in the batch simulator: the shipped ONNX policy (run with OpenCV
DNN, as the C++ side can) with the shield and without it, and the rule-based baseline, on the
same seeds. Figures per mode: success_rate (episodes with every car at its goal), collisions
(cars that collided), off_road, timeouts, shield_interventions (steps the shield braked or, shield_lane_steers, steered back into the
lane),
mean_traverse_s (start to goal, cars that arrived), steering_rate_rms (front-wheel angle rate
[rad/s] over every car's steps), policy_inference_us_p99 (one batched forward pass)."""

from __future__ import annotations

import math
import multiprocessing as mp
import time
from pathlib import Path
from typing import Any

import numpy as np

from autodrive.learn.marl.baseline import FcfsBaseline
from autodrive.learn.marl.env import MarlIntersectionEnv

EVAL_MAX_STEPS = 500  # 50 s: room for the baseline's queue of four cars
MODES = ("shield", "no_shield", "baseline")


def run_episodes(
    model: str, cars: int, mode: str, seeds: list[int], action_mode: str = "discrete"
) -> dict[str, Any]:
    """Raw sums over the episodes of seeds (one process)."""
    from autodrive.learn.marl.export import OnnxPolicy

    if mode not in MODES:
        raise ValueError(f"mode '{mode}': one of {', '.join(MODES)}")
    policy = OnnxPolicy(Path(model)) if mode != "baseline" else None
    env = MarlIntersectionEnv(
        cars=cars,
        action_mode=policy.action_mode if policy else action_mode,
        shield=(mode == "shield"),
        max_steps=EVAL_MAX_STEPS,
    )
    if mode == "baseline":
        env.baseline = FcfsBaseline()
    acc = new_tally()
    for seed in seeds:
        obs, _ = env.reset(seed=seed)
        while env.agents:
            actions: dict[str, Any] = {}
            if policy is not None:
                live = list(env.agents)
                batch = np.stack([obs[a] for a in live])
                t0 = time.perf_counter()
                act = policy.act(batch)
                acc["inference_us"].append((time.perf_counter() - t0) * 1e6)
                actions = {a: act[k] for k, a in enumerate(live)}
            obs, _, _, _, _ = env.step(actions)
        tally_episode(acc, seed, env.stats)
    env.close()
    return acc


def new_tally() -> dict[str, Any]:
    """The raw sums of no episode yet (tally_episode adds one)."""
    return {
        "episodes": 0,
        "successes": 0,
        "collisions": 0,
        "off_road": 0,
        "timeouts": 0,
        "shield_interventions": 0,
        "shield_lane_steers": 0,
        "traverse_s": [],
        "rate_sq_sum": 0.0,
        "rate_n": 0,
        "inference_us": [],
        "failed_seeds": [],
        "failures": [],
    }


def tally_episode(acc: dict[str, Any], seed: int, stats: dict[str, Any]) -> None:
    """Adds one finished episode (the env's stats) to acc: a success only when every car is
    at its goal; each car's collision, off-road or timeout counted."""
    out = stats["outcome"]
    acc["episodes"] += 1
    ok = all(o == "goal" for o in out)
    acc["successes"] += int(ok)
    if not ok:
        acc["failed_seeds"].append(seed)
        acc["failures"].append({"seed": seed, "routes": stats["routes"], "outcome": list(out)})
    acc["collisions"] += sum(o == "collision" for o in out)
    acc["off_road"] += sum(o == "off_road" for o in out)
    acc["timeouts"] += sum(o == "timeout" for o in out)
    acc["shield_interventions"] += int(stats["shield_interventions"])
    acc["shield_lane_steers"] += int(stats["shield_lane_steers"])
    acc["traverse_s"] += [t for t in stats["traverse_s"] if not math.isnan(t)]
    acc["rate_sq_sum"] += stats["steering_rate_sq_sum"]
    acc["rate_n"] += stats["steering_rate_n"]


def _star(args: tuple[str, int, str, list[int]]) -> dict[str, Any]:
    return run_episodes(*args)


def evaluate(
    model: Path, episodes: int, cars: int, seed: int, mode: str, workers: int = 1
) -> dict[str, Any]:
    """One mode's figures over seeds seed .. seed + episodes - 1."""
    seeds = list(range(seed, seed + episodes))
    chunks = [list(c) for c in np.array_split(seeds, max(1, workers)) if len(c)]
    jobs = [(str(model), cars, mode, [int(s) for s in c]) for c in chunks]
    if len(jobs) == 1:
        parts = [_star(jobs[0])]
    else:
        with mp.get_context("spawn").Pool(len(jobs)) as pool:
            parts = pool.map(_star, jobs)
    n = sum(p["episodes"] for p in parts)
    trav = [t for p in parts for t in p["traverse_s"]]
    inf = [t for p in parts for t in p["inference_us"]]
    rate_n = sum(p["rate_n"] for p in parts)
    return {
        "mode": mode,
        "cars": cars,
        "episodes": n,
        "first_seed": seed,
        "success_rate": sum(p["successes"] for p in parts) / n if n else 0.0,
        "collisions": sum(p["collisions"] for p in parts),
        "off_road": sum(p["off_road"] for p in parts),
        "timeouts": sum(p["timeouts"] for p in parts),
        "shield_interventions": sum(p["shield_interventions"] for p in parts),
        # of them, steps where the lane term replaced the steering
        "shield_lane_steers": sum(p["shield_lane_steers"] for p in parts),
        "mean_traverse_s": float(np.mean(trav)) if trav else math.nan,
        "steering_rate_rms": math.sqrt(sum(p["rate_sq_sum"] for p in parts) / rate_n)
        if rate_n
        else 0.0,
        "policy_inference_us_p99": float(np.percentile(inf, 99)) if inf else None,
        "failed_seeds": [s for p in parts for s in p["failed_seeds"]][:20],
        # every failed episode: its seed, each car's route and outcome (goal, collision,
        # off_road, timeout)
        "failures": [f for p in parts for f in p["failures"]],
        "failed_episodes_by_kind": failure_kinds([f for p in parts for f in p["failures"]]),
    }


def failure_kinds(failures: list[dict[str, Any]]) -> dict[str, int]:
    """Failed episodes by their worst outcome: collision, else off_road, else timeout."""
    kinds = {"collision": 0, "off_road": 0, "timeout": 0}
    for f in failures:
        out = f["outcome"]
        kind = next((k for k in kinds if k in out), "timeout")
        kinds[kind] += 1
    return kinds


def evaluate_all(
    model: Path, episodes: int, cars: int, seed: int, modes: list[str], log: Any, workers: int = 1
) -> dict[str, Any]:
    """Every mode on the same seeds."""
    report: dict[str, Any] = {"model": str(model), "cars": cars, "episodes": episodes}
    for mode in modes:
        report[mode] = evaluate_logged(model, episodes, cars, seed, mode, log, workers, mode)
    return report


def evaluate_logged(
    model: Path,
    episodes: int,
    cars: int,
    seed: int,
    mode: str,
    log: Any,
    workers: int = 1,
    label: str = "",
) -> dict[str, Any]:
    """evaluate(), with a progress line before and the figures after, under label."""
    t0 = time.monotonic()
    log(f"{label}: {episodes} episodes, {cars} car(s), seeds {seed}..{seed + episodes - 1}")
    r = evaluate(model, episodes, cars, seed, mode, workers)
    log(
        f"{label}: success {r['success_rate']:.3f}, collisions {r['collisions']}, off road "
        f"{r['off_road']}, timeouts {r['timeouts']}, shield {r['shield_interventions']}, "
        f"traverse {r['mean_traverse_s']:.2f} s, steering rate rms "
        f"{r['steering_rate_rms']:.3f} rad/s ({time.monotonic() - t0:.0f} s)"
    )
    return r
