"""tools/bench cloning: behavioural cloning end to end on Driving School (issue 16's goals).
1. The pipeline: record LAPS expert laps, extract the dataset and train (pilot-train's
   `python -m autodrive.learn.pilot make-model`), then deploy and evaluate LAPS laps (tools/demo
   --mission cloning); its wall time (goal <= 20 min). --model M skips recording and training
   and evaluates M (then the pipeline's time is not measured). --dagger-rounds N trains with
   `tools/pilot dagger --rounds N` instead (issue 38: record, DAgger rounds and train; goal
   <= 45 min for the pipeline).
2. inference_ms_p50/p99 of autodrive-pilot on one core (taskset -c 0, cv::setNumThreads(1)) on
   front-camera frames of the run, the median of 5 passes (goal p99 <= 5 ms).
3. The evaluation in the normal condition (goals: autonomy 100 %, cross-track rms <= 0.04 m) and
   in the issue's three unseen ones, night, noise2x and reverse (the recorded route driven the
   other way; goal: autonomy >= 95 % each), and in one more unseen, other-lane (loop_cw, the
   inner lane clockwise), other-lane-reverse (the inner lane counter-clockwise), tiny-town
   (Tiny Town's loop_ccw) and intersection (Intersection School through the junction), each
   reported with its own goal flag (issue 38's roads never trained on).
Every step's wall time is printed beside its CPU time (this process and all its children: the
simulators, the runtime, the pilot, training). On a shared machine the wall time includes the
time the pipeline waited for other jobs' CPU, so it is inflated; the CPU time is its own cost.
Writes out/bench/cloning/ (model/, work/, one demo folder per condition); last line JSON."""

from __future__ import annotations

import argparse
import importlib.util
import json
import os
import shutil
import statistics
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

from autodrive.core.proc import cpu_s
from autodrive.hil.missions import cloning
from autodrive.bench import Progress, build_dir, out_dir, print_figures
from autodrive.core import seeds
from autodrive.bench.goals import Goal, at_least, at_most, equals, judge

SUITE = "cloning"
UNSEEN = cloning.UNSEEN  # the issue's: night, noise2x, reverse
EXTRA = cloning.EXTRA  # other-lane
FRAMES = 200  # front-camera frames timed on one core
INFERENCE_PASSES = 5  # ... this many times: the figures are the passes' medians


def parse_args(argv: list[str]) -> argparse.Namespace:
    p = argparse.ArgumentParser(prog="tools/bench cloning", description=__doc__)
    p.add_argument("--laps", type=int, default=5, help="expert laps recorded and laps evaluated")
    p.add_argument("--unseen-laps", type=int, default=1, help="laps in each unseen condition")
    p.add_argument("--model", help="evaluate this NAME.onnx instead of recording and training")
    p.add_argument(
        "--seed",
        type=int,
        default=seeds.CLONING_BENCH_NEXT_SEED,
        help="the evaluation runs' seed (default the next unused one of the cloning block, "
        "autodrive.core.seeds.CLONING_BENCH_NEXT_SEED)",
    )
    p.add_argument(
        "--train-seed",
        type=int,
        default=seeds.CLONING_EXPERT_SEED,
        help="the recordings' seed (a training seed, default autodrive.core.seeds' "
        "CLONING_EXPERT_SEED)",
    )
    p.add_argument(
        "--curve-max", type=float, default=0.0, metavar="DK",
        help="train with the curvature augmentation up to DK [1/m] (make-model --curve-max; an "
        "experiment, 0: the shipped recipe)",
    )  # fmt: skip
    p.add_argument(
        "--dagger-rounds", type=int, default=0, metavar="N",
        help="train with tools/pilot dagger --rounds N (0: make-model, the shipped recipe)",
    )  # fmt: skip
    p.add_argument("--timeout", type=float, default=7200.0, help="per evaluation [wall s]")
    args = p.parse_args(argv)
    try:  # before hours of recording: training and evaluation never share a seed
        seeds.require(args.seed, ("development", "evaluation"), "--seed")
        for s in (args.train_seed, args.train_seed + 1):  # make-model records on S and S + 1
            seeds.require(s, ("training",), "--train-seed's recording seed")
    except ValueError as e:
        p.error(str(e))
    return args


def make_model(
    out: Path, laps: int, seed: int, say: Progress, curve_max: float = 0.0, dagger_rounds: int = 0
) -> tuple[Path, float]:
    """Records, extracts and trains with pilot-train's tools (make-model, or tools/pilot dagger
    with dagger_rounds > 0); (the model, wall s)."""
    if importlib.util.find_spec("autodrive.learn.pilot") is None:
        raise RuntimeError("autodrive.learn.pilot (tools/pilot, branch pilot-train) is missing")
    model_dir, work = out / "model", out / "work"
    shutil.rmtree(model_dir, ignore_errors=True)
    if dagger_rounds > 0:
        shutil.rmtree(work, ignore_errors=True)  # dagger refuses a work folder of a run
        argv = [sys.executable, "-m", "autodrive.learn.pilot", "dagger", "--out", str(model_dir)]
        argv += ["--work", str(work), "--rounds", str(dagger_rounds), "--seed", str(seed)]
    else:
        argv = [sys.executable, "-m", "autodrive.learn.pilot", "make-model"]
        argv += ["--out", str(model_dir), "--work", str(work), "--laps", str(laps)]
        argv += ["--seed", str(seed)]
    if curve_max > 0:
        argv += ["--curve-max", f"{curve_max:g}"]
    say(f"record {laps} laps + train: {' '.join(argv)}")
    t0 = time.monotonic()
    subprocess.run(argv, check=True, stdout=sys.stderr)
    models = sorted(model_dir.glob("*.onnx"))
    if not models:
        raise RuntimeError(f"make-model wrote no .onnx into {model_dir}")
    return models[0], time.monotonic() - t0


def evaluate(model: Path, condition: str, laps: int, args: argparse.Namespace, out: Path,
             save_frames: int = 0) -> dict[str, Any]:  # fmt: skip
    laps = condition_laps(condition, laps)
    argv = ["--mission", "cloning", "--build", str(build_dir(SUITE)), "--model", str(model)]
    argv += ["--out", str(out / condition), "--condition", condition, "--laps", str(laps)]
    argv += ["--seed", str(args.seed), "--timeout", str(args.timeout), "--headless"]
    argv += ["--save-frames", str(save_frames)]
    code = cloning.run(cloning.parse_args(argv), console=sys.stderr)
    rep: dict[str, Any] = json.loads((out / condition / "report.json").read_text())
    rep["exit_code"] = code
    return rep


def condition_laps(condition: str, laps: int) -> int:
    """The laps a condition drives: a route that is not a loop (intersection) is driven once."""
    return laps if cloning.condition_route(condition)[0].loop else 1


def one_core_inference(model: Path, frames_dir: Path, out: Path) -> dict[str, Any]:
    """autodrive-pilot --predict on one core over FRAMES frames, INFERENCE_PASSES times: the
    median of each pass's figures (the p99 of 200 frames is the 2nd-worst frame, and on a VM a
    thread's CPU clock runs on while the host has taken the core: single passes vary 3-9 ms),
    and every pass's p99 beside it."""
    frames = sorted(frames_dir.glob("*.jpg"))[:FRAMES]
    if not frames:
        return {"error": f"no frames in {frames_dir}"}
    stats = out / "inference-one-core.json"
    argv = ["taskset", "-c", "0", str(build_dir(SUITE) / "bin" / "autodrive-pilot")]
    argv += ["--model", str(model), "--stats", str(stats), "--predict", *map(str, frames)]
    passes: list[dict[str, Any]] = []
    for _ in range(INFERENCE_PASSES):
        subprocess.run(argv, check=True, stdout=subprocess.DEVNULL)
        passes.append(json.loads(stats.read_text()))
    result: dict[str, Any] = {
        k: statistics.median(p[k] for p in passes)
        for k, v in passes[0].items()
        if isinstance(v, (int, float))
    }
    result["inference_cpu_ms_p99_passes"] = [p.get("inference_cpu_ms_p99") for p in passes]
    return result


def make_model_times(model: Path) -> Any:
    """make-model's own wall times per step (expert, record, train, analyse), from its report."""
    try:
        report = json.loads(model.with_name(model.stem + "_report.json").read_text())
    except (OSError, ValueError):
        try:  # tools/pilot dagger: its rounds' times
            dagger = json.loads(model.with_name("dagger_report.json").read_text())
        except (OSError, ValueError):
            return None
        return [{k: v for k, v in r.items() if k.endswith("_s")} for r in dagger["rounds"]]
    return report.get("wall_times_s")


PIPELINE_GOAL_S = 1200.0  # issue 16: record, train, deploy and evaluate in 20 min
DAGGER_PIPELINE_GOAL_S = 2700.0  # issue 38: record, the DAgger rounds and train in 45 min


def goal_table(laps: int = 5, unseen_laps: int = 1, dagger: bool = False) -> dict[str, Goal]:
    """Issue 16's goals (and the extra conditions' same bar; issue 38's pipeline goal with
    DAgger). A condition counts only with its laps driven and its run's exit code 0: a run that
    timed out or crashed fails its goals."""
    goals = {
        "autonomy_100_normal": equals("normal.autonomy_pct", 100.0),
        "normal_laps_driven": at_least("normal.laps", laps),
        "normal_exit_0": equals("normal.exit_code", 0),
        "cross_track_le_0_04": at_most("normal.cross_track_rms_m", 0.04),
        # on one core: the pilot thread's CPU time (wall time includes a loaded host's queue)
        "inference_p99_le_5ms": at_most("inference_cpu_ms_p99", 5.0),
    }
    if dagger:
        goals["pipeline_le_45min"] = at_most("pipeline_wall_s", DAGGER_PIPELINE_GOAL_S)
    else:
        goals["pipeline_le_20min"] = at_most("pipeline_wall_s", PIPELINE_GOAL_S)
    for cond in UNSEEN + EXTRA:
        kind = "unseen" if cond in UNSEEN else "extra"  # extra: not one of the goals
        goals[f"{kind}_{cond}_ge_95"] = at_least(f"{cond}.autonomy_pct", 95.0)
        goals[f"{kind}_{cond}_laps_driven"] = at_least(
            f"{cond}.laps", condition_laps(cond, unseen_laps)
        )
        goals[f"{kind}_{cond}_exit_0"] = equals(f"{cond}.exit_code", 0)
    return goals


def main(argv: list[str]) -> int:
    args = parse_args(argv)
    say = Progress(SUITE)
    out = out_dir() / SUITE
    out.mkdir(parents=True, exist_ok=True)
    figures: dict[str, Any] = {"laps": args.laps, "unseen_laps": args.unseen_laps}
    figures["curve_max"] = args.curve_max
    figures["dagger_rounds"] = args.dagger_rounds
    steps: dict[str, dict[str, float]] = {}  # each step's wall and CPU seconds
    t0, cpu0 = time.monotonic(), cpu_s()
    figures["load_avg_start"] = round(os.getloadavg()[0], 1)

    def step(name: str, t_start: float, cpu_start: float) -> None:
        steps[name] = {
            "wall_s": round(time.monotonic() - t_start, 1),
            "cpu_s": round(cpu_s() - cpu_start, 1),
        }
        say(f"{name}: {steps[name]['wall_s']} s wall, {steps[name]['cpu_s']} s CPU")

    try:
        if args.model:
            model, train_s = Path(args.model), None
        else:
            model, train_s = make_model(
                out, args.laps, args.train_seed, say, args.curve_max, args.dagger_rounds
            )
            step("record_train", t0, cpu0)
    except (RuntimeError, subprocess.CalledProcessError) as e:
        say(f"ERROR: {e}")
        return 1
    figures["model"] = str(model)
    figures["record_train_s"] = None if train_s is None else round(train_s, 1)
    figures["record_train_cpu_s"] = None if train_s is None else round(cpu_s() - cpu0, 1)
    figures["make_model_wall_times_s"] = make_model_times(model) if train_s else None
    say(f"evaluate {args.laps} laps, normal condition")
    t1, cpu1 = time.monotonic(), cpu_s()
    normal = evaluate(model, "normal", args.laps, args, out, save_frames=FRAMES)
    step("evaluate_normal", t1, cpu1)
    figures["pipeline_wall_s"] = None if train_s is None else round(time.monotonic() - t0, 1)
    figures["pipeline_cpu_s"] = None if train_s is None else round(cpu_s() - cpu0, 1)
    figures["load_avg_end"] = round(os.getloadavg()[0], 1)
    figures["normal"] = normal
    one = one_core_inference(model, out / "normal" / "frames", out)
    figures["inference_ms_p50"] = one.get("inference_ms_p50")
    figures["inference_ms_p99"] = one.get("inference_ms_p99")
    figures["inference_cpu_ms_p50"] = one.get("inference_cpu_ms_p50")
    figures["inference_cpu_ms_p99"] = one.get("inference_cpu_ms_p99")
    figures["inference_frames"] = one.get("frames")
    figures["inference_cpu_ms_p99_passes"] = one.get("inference_cpu_ms_p99_passes")
    for cond in UNSEEN + EXTRA:
        say(f"evaluate {args.unseen_laps} lap(s), unseen condition {cond}")
        tc, cpuc = time.monotonic(), cpu_s()
        figures[cond] = evaluate(model, cond, args.unseen_laps, args, out)
        step(f"evaluate_{cond}", tc, cpuc)
    figures["steps"] = steps

    goals = goal_table(args.laps, args.unseen_laps, args.dagger_rounds > 0)
    judge(figures, goals, seeds.span(args.seed, 1))
    for c in ("normal", *UNSEEN, *EXTRA):
        r = figures[c]
        print(f"{c}: laps {r.get('laps')}  interventions {r.get('interventions')}  autonomy "
              f"{r.get('autonomy_pct')} %  cross-track rms {r.get('cross_track_rms_m')} m  mean "
              f"speed {r.get('mean_speed_m_s')} m/s  in-run inference p99 "
              f"{r.get('inference_ms_p99')} ms  wall {r.get('wall_s')} s")  # fmt: skip
    print(f"one core: inference p50 {figures['inference_ms_p50']} ms, p99 "
          f"{figures['inference_ms_p99']} ms wall; CPU p50 {figures['inference_cpu_ms_p50']} ms, "
          f"p99 {figures['inference_cpu_ms_p99']} ms")  # fmt: skip
    for name, st in steps.items():
        print(f"{name}: {st['wall_s']} s wall, {st['cpu_s']} s CPU")
    print(f"pipeline (record {args.laps} laps, train, deploy, evaluate {args.laps} laps): "
          f"{figures['pipeline_wall_s']} s wall, {figures['pipeline_cpu_s']} s CPU; load "
          f"average {figures['load_avg_start']} -> {figures['load_avg_end']} on "
          f"{os.cpu_count()} cores: the machine is shared, so the wall time includes waiting "
          "for other jobs' CPU (inflated); the CPU time is the pipeline's own")  # fmt: skip
    print_figures({k: v for k, v in figures.items()})
    return 0
