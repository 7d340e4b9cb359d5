"""tools/bench marl: trains the intersection policy from scratch with the shipped recipe (the
training config recorded in models/marl/intersection.json), then evaluates it on 200 evaluation
seeds (autodrive.core.seeds.EVALUATION) in the batch simulator with the shield: the issue's goal "training from scratch to the
batch goal (4 cars, success >= 0.98, 0 collisions, shield on) in <= 45 min wall".
Progress on stderr; figures on stdout, the last line one JSON object.

training_wall_s / training_cpu_s (this process and its joined rollout workers) /
training_agent_steps; training_stopped_s (wall time the process was stopped from outside, e.g.
by another session's SIGSTOP) and training_wall_running_s (the wall time without it);
load_avg_1min_* (before and after training, and after the evaluation:
wall figures depend on the machine's load); success_rate_* (episodes with every car at its
goal), collisions_* (cars), off_road_*, timeouts_*, shield_interventions_* (car-steps the
shield acted), mean_traverse_s_*, steering_rate_rms_* [rad/s]; policy_inference_us_p99: one
OpenCV DNN forward pass of 4 observations, median over MARL_BENCH_REPEATS (3) runs of 2000.

Options (environment): MARL_BENCH_TRAIN (1: train from scratch; 0: measure MARL_BENCH_MODEL,
default the shipped models/marl/intersection.onnx, without training), MARL_BENCH_EPISODES
(200), MARL_BENCH_FIRST_SEED (every mode's first seed, default
autodrive.core.seeds.MARL_BENCH_FIRST_SEED; the JSON records the seeds' range),
MARL_BENCH_WORKERS (2, evaluation processes), MARL_BENCH_COMPARE (1: adds the same
seeds without the shield, the FCFS baseline, and 1 car on MARL_BENCH_EPISODES_1CAR (50); 0 leaves
them out, and goals_met is then false: the baseline goals' figures are missing)."""

from __future__ import annotations

import dataclasses
import json
import os
import statistics
import sys
import threading
import time
from pathlib import Path
from typing import Any

import numpy as np

from autodrive.bench import Progress, build_dir, out_dir, print_figures
from autodrive.core import seeds
from autodrive.bench.goals import at_least, at_most, equals, judge

log = Progress("marl")
TRAIN_GOAL_WALL_S = 45 * 60  # issue 17: training from scratch to the batch goal
SUCCESS_GOAL = 0.98  # issue 17: batch success with 4 cars and the shield
# Issue 17's goals. Without training the training time is the shipped model's recorded one;
# with MARL_BENCH_COMPARE=0 the baseline's figures are missing and fail their goals.
GOALS = {
    "success_4cars_shield_ge_0.98": at_least("success_rate_4cars_shield", SUCCESS_GOAL),
    "collisions_4cars_shield_0": equals("collisions_4cars_shield", 0),
    "training_from_scratch_le_45_min": at_most("training_wall_s", TRAIN_GOAL_WALL_S),
    "policy_as_fast_as_baseline": at_most("traverse_ratio_policy_over_baseline", 1.0),
    "policy_collisions_le_baseline": at_most("collisions_policy_minus_baseline", 0),
    "policy_success_ge_baseline": at_least("success_rate_policy_minus_baseline", 0.0),
}


def inference_p99_us(model: Path, repeats: int) -> float:
    from autodrive.learn.marl.export import OnnxPolicy

    policy = OnnxPolicy(model)
    obs = np.random.default_rng(0).normal(size=(4, 24)).astype(np.float32)
    runs = []
    for _ in range(repeats):
        t = []
        for _ in range(2000):
            t0 = time.perf_counter()
            policy.act(obs)
            t.append((time.perf_counter() - t0) * 1e6)
        runs.append(float(np.percentile(t, 99)))
    return statistics.median(runs)


class StoppedClock:
    """Wall time this process spent stopped (SIGSTOP from outside, e.g. another session's
    quiet-machine measurement on this shared machine): a thread ticks every TICK_S and counts
    each gap over GAP_S as stopped. Wall figures are given with and without it."""

    TICK_S = 0.2
    GAP_S = 1.5  # far above any scheduling delay of a niced thread seen here

    def __init__(self) -> None:
        self.stopped_s = 0.0
        self._done = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self) -> None:
        last = time.monotonic()
        while not self._done.wait(self.TICK_S):
            now = time.monotonic()
            if now - last > self.GAP_S:
                self.stopped_s += now - last - self.TICK_S
            last = now

    def close(self) -> float:
        self._done.set()
        self._thread.join()
        return round(self.stopped_s, 1)


def first_seed(episodes: int) -> int:
    """MARL_BENCH_FIRST_SEED (default seeds.MARL_BENCH_FIRST_SEED): every mode's first seed;
    SystemExit naming it when it is not an integer or its episodes straddle two seed ranges."""
    text = os.environ.get("MARL_BENCH_FIRST_SEED", str(seeds.MARL_BENCH_FIRST_SEED))
    try:
        first = int(text)
        seeds.span(first, episodes)
    except ValueError as e:
        raise SystemExit(
            f"[bench marl] ERROR: MARL_BENCH_FIRST_SEED='{text}': want a seed whose "
            f"{episodes} episodes lie in one range of autodrive.core.seeds ({e})"
        ) from None
    return first


def load_1min() -> float:
    return round(os.getloadavg()[0], 2)


def train_from_scratch(shipped: Path, dest: Path) -> dict[str, Any]:
    """Trains with the shipped model's recorded recipe (every field of trained.config, its wall
    cap and checkpoint selection too) into dest (.onnx, with the curve and report beside it);
    returns the training report (wall_s, cpu_s, agent_steps_done, validation, config, command).
    """
    from autodrive.learn.marl.train import TrainConfig, train, write_results

    recorded = json.loads(shipped.with_suffix(".json").read_text()).get("trained", {})
    cfg_rec = recorded.get("config")
    if not isinstance(cfg_rec, dict):
        raise SystemExit(
            f"[bench marl] ERROR: {shipped.with_suffix('.json')} has no trained.config: "
            "the shipped recipe is unknown"
        )
    fields = {f.name for f in dataclasses.fields(TrainConfig)}
    unknown = sorted(set(cfg_rec) - fields)
    if unknown:
        raise SystemExit(
            f"[bench marl] ERROR: {shipped.with_suffix('.json')}: trained.config has unknown "
            f"field(s) {', '.join(unknown)}"
        )
    # every recorded field is the recipe, the wall cap and checkpoint selection included
    rec = {k: v for k, v in cfg_rec.items() if k != "ray_address"}
    rec["stages"] = [(int(c), int(n)) for c, n in cfg_rec["stages"]]
    cfg = TrainConfig(**rec)
    log(
        f"training from scratch: stages {cfg.stages}, {cfg.action_mode}, copies {cfg.copies}, "
        f"workers {cfg.workers}, shield {cfg.shield}, shaping {cfg.shaping}, seed {cfg.seed}, "
        f"wall cap {cfg.max_wall_s} s, validation episodes {cfg.validate_episodes} from "
        f"{cfg.validate_from} every {cfg.validate_every} steps"
    )
    model, curve, info = train(cfg, log, dest.parent)
    info["command"] = "tools/bench marl (recipe: " + str(recorded.get("command", "?")) + ")"
    write_results(model, curve, info, dest, dest.parent, cfg.action_mode)
    return info


def main(argv: list[str]) -> int:
    from autodrive.learn.marl.cli import DEFAULT_MODEL
    from autodrive.learn.marl.evaluate import evaluate_logged

    if argv:
        print(__doc__)
        return 0 if argv[0] in ("-h", "--help") else 2
    build_dir("marl")
    do_train = os.environ.get("MARL_BENCH_TRAIN", "1") != "0"
    shipped = Path(os.environ.get("MARL_BENCH_MODEL", DEFAULT_MODEL))
    if not shipped.is_file():
        raise SystemExit(f"[bench marl] ERROR: no policy {shipped} (MARL_BENCH_MODEL)")
    episodes = int(os.environ.get("MARL_BENCH_EPISODES", "200"))
    episodes_1 = int(os.environ.get("MARL_BENCH_EPISODES_1CAR", "50"))
    workers = int(os.environ.get("MARL_BENCH_WORKERS", "2"))
    compare = os.environ.get("MARL_BENCH_COMPARE", "1") != "0"
    first = first_seed(max(episodes, episodes_1))  # every mode on the same seeds
    figures: dict[str, Any] = {"trained_from_scratch": do_train, "load_avg_1min_start": load_1min()}
    if do_train:
        model = out_dir() / "marl-train" / "intersection.onnx"
        t0 = time.monotonic()
        stopped = StoppedClock()
        info = train_from_scratch(shipped, model)
        figures["training_wall_s"] = round(time.monotonic() - t0, 1)
        figures["training_stopped_s"] = stopped.close()
        figures["training_wall_running_s"] = round(
            figures["training_wall_s"] - figures["training_stopped_s"], 1
        )
        figures["training_cpu_s"] = info["cpu_s"]
        figures["training_agent_steps"] = info["agent_steps_done"]
        figures["training_recipe"] = info["command"]
    else:
        model = shipped
        trained = json.loads(model.with_suffix(".json").read_text()).get("trained", {})
        figures["training_wall_s"] = trained.get("wall_s")
        figures["training_cpu_s"] = trained.get("cpu_s")
        figures["training_agent_steps"] = trained.get("agent_steps_done")
    figures["load_avg_1min_after_training"] = load_1min()
    figures.update(episodes_4cars=episodes, model=str(model))
    plan = [("4cars_shield", 4, "shield", episodes)]
    if compare:
        plan += [
            ("4cars_no_shield", 4, "no_shield", episodes),
            ("4cars_baseline", 4, "baseline", episodes),
            ("1car_shield", 1, "shield", episodes_1),
        ]
    runs: dict[str, dict[str, Any]] = {}
    t_eval = time.monotonic()
    for name, cars, mode, n in plan:
        runs[name] = evaluate_logged(model, n, cars, first, mode, log, workers, name)
    figures["evaluation_wall_s"] = round(time.monotonic() - t_eval, 1)
    figures["load_avg_1min_after_evaluation"] = load_1min()
    for name, r in runs.items():
        for k in (
            "success_rate",
            "collisions",
            "off_road",
            "timeouts",
            "shield_interventions",
            "mean_traverse_s",
            "steering_rate_rms",
        ):
            figures[f"{k}_{name}"] = r[k]
    figures["policy_inference_us_p99"] = round(
        inference_p99_us(model, int(os.environ.get("MARL_BENCH_REPEATS", "3"))), 1
    )
    s = runs["4cars_shield"]
    if compare:
        b = runs["4cars_baseline"]
        figures["traverse_ratio_policy_over_baseline"] = s["mean_traverse_s"] / b["mean_traverse_s"]
        figures["collisions_policy_minus_baseline"] = s["collisions"] - b["collisions"]
        figures["success_rate_policy_minus_baseline"] = s["success_rate"] - b["success_rate"]
    judge(figures, GOALS, seeds.span(first, max(n for _, _, _, n in plan)))
    (out_dir() / "marl.json").write_text(json.dumps({"figures": figures, "runs": runs}, indent=2))
    print_figures(figures, key_value_lines=True)
    sys.stdout.flush()
    return 0
