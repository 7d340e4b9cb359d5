"""tools/bench marl: the shipped intersection policy (models/marl/intersection.onnx) on
held-out seeds in the batch simulator, against the rule-based baseline on the same seeds.
Progress on stderr; figures on stdout, the last line one JSON object.

success_rate_4cars_shield / _no_shield / _1car_shield: episodes with every car at its goal;
collisions_*: cars that collided; shield_interventions_*: steps the shield braked;
mean_traverse_s_policy (4 cars, shield) vs mean_traverse_s_baseline (FCFS, same seeds) and
their ratio; steering_rate_rms_* [rad/s]; training_wall_s / training_cpu_s: the shipped
model's training wall and CPU time (its sidecar; the wall time is inflated on a shared machine); policy_inference_us_p99: one forward pass of 4 observations with OpenCV
DNN, median of MARL_BENCH_REPEATS runs of 2000. Options: MARL_BENCH_EPISODES (200),
MARL_BENCH_EPISODES_1CAR (50), MARL_BENCH_WORKERS (2), MARL_BENCH_MODEL."""

from __future__ import annotations

import json
import os
import statistics
import time
from pathlib import Path
from typing import Any

import numpy as np

from . import Progress, build_dir, out_dir, print_figures

log = Progress("marl")
HELD_OUT_SEED = 1_000_000_000


def inference_p99_us(model: Path, repeats: int) -> float:
    from ..marl.export import OnnxPolicy

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


def main(argv: list[str]) -> int:
    from ..marl.evaluate import evaluate_logged

    if argv:
        print(__doc__)
        return 0 if argv[0] in ("-h", "--help") else 2
    build_dir("marl")
    from ..paths import REPO_ROOT

    model = Path(os.environ.get("MARL_BENCH_MODEL", REPO_ROOT / "models/marl/intersection.onnx"))
    if not model.is_file():
        raise SystemExit(f"[bench marl] ERROR: no policy {model}: train one with tools/marl train")
    episodes = int(os.environ.get("MARL_BENCH_EPISODES", "200"))
    episodes_1 = int(os.environ.get("MARL_BENCH_EPISODES_1CAR", "50"))
    workers = int(os.environ.get("MARL_BENCH_WORKERS", "2"))
    meta: dict[str, Any] = json.loads(model.with_suffix(".json").read_text())
    runs: dict[str, dict[str, Any]] = {}
    for name, cars, mode, n in (
        ("4cars_shield", 4, "shield", episodes),
        ("4cars_no_shield", 4, "no_shield", episodes),
        ("4cars_baseline", 4, "baseline", episodes),
        ("1car_shield", 1, "shield", episodes_1),
    ):
        runs[name] = evaluate_logged(model, n, cars, HELD_OUT_SEED, mode, log, workers, name)
    p99 = inference_p99_us(model, int(os.environ.get("MARL_BENCH_REPEATS", "3")))
    s, b = runs["4cars_shield"], runs["4cars_baseline"]
    figures: dict[str, Any] = {
        "episodes_4cars": episodes,
        "episodes_1car": episodes_1,
        "first_seed": HELD_OUT_SEED,
    }
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
    figures["mean_traverse_s_policy"] = s["mean_traverse_s"]
    figures["mean_traverse_s_baseline"] = b["mean_traverse_s"]
    figures["traverse_ratio_policy_over_baseline"] = s["mean_traverse_s"] / b["mean_traverse_s"]
    figures["training_wall_s"] = meta.get("trained", {}).get("wall_s")
    figures["training_cpu_s"] = meta.get("trained", {}).get("cpu_s")
    figures["training_agent_steps"] = meta.get("trained", {}).get("agent_steps_done")
    figures["policy_inference_us_p99"] = round(p99, 1)
    figures["goals_met"] = {
        "success_4cars_shield_ge_0.98_0_collisions": s["success_rate"] >= 0.98
        and s["collisions"] == 0,
        "policy_as_fast_as_baseline_at_same_safety": s["mean_traverse_s"] <= b["mean_traverse_s"]
        and s["collisions"] <= b["collisions"]
        and s["success_rate"] >= b["success_rate"],
        "training_le_45_min": (figures["training_wall_s"] or 1e9) <= 45 * 60
        and s["success_rate"] >= 0.98,
    }
    (out_dir() / "marl.json").write_text(json.dumps({"figures": figures, "runs": runs}, indent=2))
    print_figures(figures, key_value_lines=True)
    return 0
