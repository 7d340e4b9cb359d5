"""`tools/pilot make-model`: the one command that makes the shipped model. The expert drives
5 laps of Driving School's loop_ccw (seeded perturbations, day light, the base camera noise) as
two recordings at once, one per core (ceil(laps/2) laps with --seed S, the rest with S + 1:
rendering the camera is nearly all of a recording's CPU time and one simulator uses one core),
the logs become one dataset, the network trains (seeded) and is exported, the analysis runs on
the validation lap, and NAME.onnx, NAME.json, the training report and the figures are copied
into --out (models/pilot). Wall times of each step go into the report. --logs reuses
recordings made before (their meta files must match the recipe's runs field by field).
--other-lane-laps N (an experiment; the shipped model has none) drives N of the laps in the
road's other lane, still counter-clockwise (expert_runs). --label-lookahead M (an experiment;
the shipped model: 0, the expert's own steering) trains on pure pursuit labels at M from each
frame's pose (labels.py)."""

from __future__ import annotations

import json
import shutil
from dataclasses import asdict
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from autodrive.core import seeds
from autodrive.learn.pilot.analyse import analyse
from autodrive.learn.pilot.dataset import record
from autodrive.learn.pilot.expert import ExpertRun, default_url, meta_path, record_expert
from autodrive.learn.pilot.train import TrainConfig, train


def log(msg: str) -> None:
    print(f"pilot make-model: {msg}", file=sys.stderr, flush=True)


# The recipe of the shipped model. The expert's camera renders at ExpertRun's 7.5 Hz of sim time
# and every frame is trained on (the old recipe rendered 15 Hz and used every 2nd); 4 epochs of
# 2560 draws, balanced with train's default cap (augment.DEFAULT_MAX_RATIO).
STRIDE = 1
SAMPLES_PER_EPOCH = 2560


# --other-lane-laps N (an experiment, not the shipped recipe; docs/guides/training.md:
# the reverse direction): N of the laps in the lane left of loop_ccw's, still driven
# counter-clockwise. The clockwise direction (loop_cw) is never recorded: it is an unseen test
# condition. Seen in a mirror, that lane's left-hand curves with the centre line on the car's
# right are the right-hand curves, centre line on the left, of the inner lane driven clockwise.
OTHER_LANE = 1


def expert_runs(laps: int, seed: int, other_lane_laps: int = 0) -> list[ExpertRun]:
    """The recordings of `laps` laps, two at once (one per core). Without other-lane laps:
    ceil(laps/2) with seed `seed`, the rest with seed + 1, all in the route's lane. With N:
    N laps in the other lane (seed + 1) first, so the seeded validation lap (lap 3 of 5 with
    --train-seed 0) is one of the route's own lane, then laps - N in the route's lane (seed)."""
    if laps < 2:
        raise ValueError(f"--laps {laps}: at least 2 (validation is a whole lap)")
    if other_lane_laps:
        if not 0 < other_lane_laps < laps:
            raise ValueError(f"--other-lane-laps {other_lane_laps}: 1..{laps - 1} of --laps {laps}")
        return [
            ExpertRun(laps=other_lane_laps, seed=seed + 1, lane_shift=OTHER_LANE),
            ExpertRun(laps=laps - other_lane_laps, seed=seed),
        ]
    first = (laps + 1) // 2
    return [
        ExpertRun(laps=first, seed=seed),
        ExpertRun(laps=laps - first, seed=seed + 1),
    ]


def record_experts(runs: list[ExpertRun], logs: list[Path], build: Path) -> None:
    """Records the runs at the same time, each on a bus of its own."""
    with ThreadPoolExecutor(max_workers=len(runs)) as pool:
        jobs = [
            pool.submit(record_expert, run, logf, build, default_url(k))
            for k, (run, logf) in enumerate(zip(runs, logs))
        ]
        for job in jobs:
            job.result()


def check_logs(runs: list[ExpertRun], logs: list[Path]) -> float:
    """Recordings made before must be the recipe's runs (their LOG.meta.json, field by field);
    returns their wall time [s] (the longer: they ran at once). ValueError names the log."""
    if len(logs) != len(runs):
        raise ValueError(f"--logs: {len(logs)} given, the recipe records {len(runs)}")
    wall = 0.0
    for run, logf in zip(runs, logs):
        try:
            meta = json.loads(meta_path(logf).read_text())
        except (OSError, ValueError) as e:
            raise ValueError(f"{logf}: no readable {meta_path(logf).name} ({e})") from e
        for key, want in asdict(run).items():
            # a recording made before lane_shift existed drove the route's own lane
            have = meta.get(key, 0 if key in ("lane_shift", "camera_blur") else None)
            if have != want:
                raise ValueError(f"{logf}: {key} is {have!r}, the recipe's {want!r}")
        wall = max(wall, float(meta.get("wall_s", 0.0)))
    return wall


def make_model(
    out: Path, work: Path, name: str, laps: int, seed: int, train_seed: int, epochs: int,
    build: Path, reuse_logs: list[Path] | None = None, other_lane_laps: int = 0,
    label_lookahead_m: float = 0.0, curve_max_dk: float = 0.0,
) -> None:  # fmt: skip
    stamp = time.strftime("%Y%m%dT%H%M%S", time.gmtime())
    run_dir = work / f"{name}-{stamp}"
    run_dir.mkdir(parents=True, exist_ok=False)
    times: dict[str, float] = {}
    t0 = time.monotonic()
    runs = expert_runs(laps, seed, other_lane_laps)
    for r in runs:  # before anything is recorded: the recordings' seeds are training seeds
        seeds.require(r.seed, ("training",), "the expert recording's seed")
    if reuse_logs:
        logs = reuse_logs
        times["expert_s"] = check_logs(runs, logs)
        log(f"1/4 expert: reusing {', '.join(map(str, logs))} (recorded in {times['expert_s']} s)")
    else:
        logs = [run_dir / f"expert_seed{r.seed}.lcmlog" for r in runs]
        for r, logf in zip(runs, logs):
            log(f"1/4 expert: {r.laps} laps, lane shift {r.lane_shift}, seed {r.seed} -> {logf}")
        record_experts(runs, logs, build)
        times["expert_s"] = time.monotonic() - t0
    t1 = time.monotonic()
    log("2/4 record")
    record(logs, run_dir / "dataset", build=build)
    times["record_s"] = time.monotonic() - t1
    t2 = time.monotonic()
    log("3/4 train")
    report = train(
        run_dir / "dataset",
        run_dir / "model",
        TrainConfig(
            epochs=epochs,
            seed=train_seed,
            name=name,
            stride=STRIDE,
            samples_per_epoch=SAMPLES_PER_EPOCH,
            label_lookahead_m=label_lookahead_m,
            curve_max_dk=curve_max_dk,
        ),
    )
    times["train_s"] = time.monotonic() - t2
    t3 = time.monotonic()
    log("4/4 analyse")
    result = analyse(run_dir / "model" / f"{name}.onnx", run_dir / "dataset", run_dir / "analysis")
    times["analyse_s"] = time.monotonic() - t3
    times["total_s"] = time.monotonic() - t0 + (times["expert_s"] if reuse_logs else 0.0)
    out.mkdir(parents=True, exist_ok=True)
    for f in (f"{name}.onnx", f"{name}.json"):
        shutil.copy2(run_dir / "model" / f, out / f)
    figs = out / f"{name}_figures"
    figs.mkdir(exist_ok=True)
    for f in ("loss.png", "steering_hist.png"):
        shutil.copy2(run_dir / "model" / f, figs / f)
    for f in result["figures"]:
        shutil.copy2(run_dir / "analysis" / f, figs / f)
    full = dict(report, analysis=result, wall_times_s={k: round(v, 1) for k, v in times.items()})
    full["command"] = (
        f"tools/pilot make-model --laps {laps} --seed {seed} --train-seed {train_seed} --epochs {epochs}"
        + (f" --other-lane-laps {other_lane_laps}" if other_lane_laps else "")
        + f" --label-lookahead {label_lookahead_m:g}"
        + (f" --curve-max {curve_max_dk:g}" if curve_max_dk else "")
    )
    if reuse_logs:
        full["recordings_reused"] = [str(p) for p in reuse_logs]
    (out / f"{name}_report.json").write_text(json.dumps(full, indent=2) + "\n")
    md = (
        (run_dir / "model" / f"{name}_report.md")
        .read_text()
        .replace("](loss.png)", f"]({figs.name}/loss.png)")
    )
    md += (
        f"\n## Reproduce\n\n`{full['command']}` (wall times on this machine: "
        + ", ".join(f"{k} {v:.0f}" for k, v in times.items())
        + f").\n\n## Analysis (validation lap {result['lap']})\n\nRMSE {result['rmse']} "
        f"(normalised steering) over {result['frames']} frames.\n\n"
        + "\n".join(f"![{f}]({figs.name}/{f})" for f in result["figures"])
        + "\n"
    )
    (out / f"{name}_report.md").write_text(md)
    log(f"done in {times['total_s']:.0f} s: {out / (name + '.onnx')}")
