"""`tools/pilot dagger`: DAgger (Ross, Gordon and Bagnell, 2011) for the cloning pilot.

Round 0 is plain cloning: the expert's laps (tools/pilot expert, or --logs of it), recorded and
trained. Round r >= 1 drives the round r - 1 model in HIL (the cloning mission: the simulator on
its own clock in lockstep, the unchanged runtime, autodrive-pilot) on the trained route, with
lcm-logger recording the camera and ground truth. Where a wheel's outer edge comes within the
takeover margin (TAKEOVER_MARGIN_M) of the lane bound, the expert takes over: the car is put
back on the centre line (the simulator's SIM_TELEPORT, as the mission's referee does at an
intervention; a reset, not a recovery the expert drives), and the takeover counts as an
intervention. Every frame of the rollout gets the expert's label beside it: the steering of the
expert's pure pursuit (its 0.2 m lookahead) from the frame's ground-truth pose (labels.py). The
rollout's dataset joins the earlier rounds' (merge: one dataset, the rounds' laps and logs
renumbered), the next model is trained on the whole, and so on for N rounds.

Autonomy per round is the rollout's, scored honestly (round_score): the laps must be completed
(else 0), a stall (6 s of sim time under 5 cm of progress, lane_watch.StallWatch) and a takeover
count as interventions. Seeded and repeatable: the expert's laps on S (and S + 1), round r's
rollout on S + ROLLOUT_SEED_OFFSET + r, all training seeds; the simulator's domain randomisation
(SimRandom: light level, camera noise and blur per recording; with --road-styles the road's
markings, road_styles.draw) is drawn from each recording's seed; training is seeded by --train-seed (numpy, torch, the draws, the image-level
randomisation, augment.Randomise)."""

from __future__ import annotations

import argparse
import csv
import json
import os
import random
import shutil
import sys
import time
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

from autodrive.learn.pilot.spec import sha256_file
from autodrive.core.proc import cpu_s
from autodrive.core import seeds
from autodrive.learn.pilot import augment, dataset
from autodrive.learn.pilot.expert import ExpertRun, meta_path
from autodrive.maps import road_styles

# The expert takes over where a wheel's outer edge comes within this of the lane bound [m]:
# before the car leaves the lane (a wheel over it is the referee's intervention), late enough
# that the learner's own drift towards the bound is in the data. On a straight, base_link is
# then 0.051 - 0.02 = 0.031 m off the centre line (lane half width 0.14 m, the wheels' outer
# edges 0.089 m either side of base_link).
TAKEOVER_MARGIN_M = 0.02
ROLLOUT_SEED_OFFSET = 1000  # round r's rollout runs on seed S + this + r (training range)
ROLLOUT_TIMEOUT_S = 3600.0  # a rollout's hang guard [s wall]; no figure depends on it
REPORT = "dagger_report"
EVAL_CAMERA_NOISE = 2.0  # sigma [8-bit levels]: the shipped recipe's, the mission's "normal"


@dataclass(frozen=True)
class SimRandom:
    """What the simulator varies per recording (autodrive-sim --light-level, --camera-noise,
    --camera-blur), each uniform in its range, drawn from the recording's seed. Night (0.25,
    the cloning mission's) stays below the light range and noise2x (4.0) above the noise one:
    those conditions stay unseen."""

    light_level: tuple[float, float] = (0.55, 1.0)  # 0..1 (1: day)
    camera_noise: tuple[float, float] = (1.0, 3.0)  # sigma [8-bit levels]
    camera_blur_px: tuple[float, float] = (0.0, 0.8)  # sigma [px of the 640x480 frame]

    def draw(self, seed: int) -> dict[str, float]:
        rng = random.Random(f"dagger-sim-{seed}")  # str seeding: the same on every platform
        return {
            "light_level": round(rng.uniform(*self.light_level), 3),
            "camera_noise": round(rng.uniform(*self.camera_noise), 3),
            "camera_blur": round(rng.uniform(*self.camera_blur_px), 3),
        }


@dataclass(frozen=True)
class DaggerConfig:
    rounds: int = 2  # DAgger rounds after round 0 (plain cloning)
    seed: int = seeds.CLONING_EXPERT_SEED  # the expert's recording; rollouts from it (training)
    expert_laps: int = 2  # round 0's expert laps (without --logs)
    rollout_laps: int = 1  # laps each rollout drives
    epochs: int = 2
    samples_per_epoch: int = 2560
    train_seed: int = 0
    takeover_margin_m: float = TAKEOVER_MARGIN_M
    randomise: bool = True  # the simulator's (SimRandom) and the image-level (augment.Randomise)
    # each recording's road markings drawn from its seed (road_styles.draw); off in the
    # recorded recipes, whose figures were measured on the kit's markings
    road_styles: bool = False
    threads: int = 1  # PyTorch threads (the machine's 2 cores are shared)
    name: str = "dagger"
    # training's balancing (augment.balance_weights): a frame drawn at most this many times as
    # often as one of the commonest steering; the tight turns are rare frames
    balance_max_ratio: float = augment.DEFAULT_MAX_RATIO

    def check(self) -> None:
        if self.rounds < 0 or self.expert_laps < 2 or self.rollout_laps < 1 or self.epochs < 1:
            raise ValueError(
                f"rounds {self.rounds} (>= 0), expert laps {self.expert_laps} (>= 2: validation "
                f"by lap), rollout laps {self.rollout_laps} (>= 1), epochs {self.epochs} (>= 1)"
            )
        if not self.balance_max_ratio >= 1:
            raise ValueError(f"balance max ratio {self.balance_max_ratio}: must be >= 1")
        if not self.takeover_margin_m >= 0:
            raise ValueError(f"takeover margin {self.takeover_margin_m} m: must be >= 0")
        seeds.require(self.seed, ("training",), "the DAgger seed")
        for r in range(1, self.rounds + 1):
            seeds.require(rollout_seed(self.seed, r), ("training",), f"round {r}'s rollout seed")


def rollout_seed(seed: int, round_: int) -> int:
    return seed + ROLLOUT_SEED_OFFSET + round_


def round_score(rollout: dict[str, Any], laps_requested: float) -> dict[str, Any]:
    """A round's honest autonomy from its rollout's report (the cloning mission's figures, in
    which every takeover and stall is an intervention): the laps must be completed and the run
    must have ended well, else autonomy 0 (a car that stalled, crashed or timed out drove
    nothing by itself). ValueError for a report without the figures."""
    try:
        laps = float(rollout["laps"])
        autonomy = rollout["autonomy_pct"]
        interventions = int(rollout["interventions"])
    except (KeyError, TypeError, ValueError) as e:
        raise ValueError(f"rollout report without its figures ({e})") from None
    completed = bool(rollout.get("ok")) and laps >= laps_requested - 1e-9
    return {
        "autonomy_pct": round(float(autonomy), 2) if completed and autonomy is not None else 0.0,
        "completed": completed,
        "laps": laps,
        "interventions": interventions,
        "takeovers": int(rollout.get("takeovers") or 0),
        "stalls": int(rollout.get("stalls") or 0),
        "cross_track_rms_m": rollout.get("cross_track_rms_m"),
    }


def merge(parts: list[tuple[int, Path]], out: Path) -> dict[str, Any]:
    """Aggregates datasets of tools/pilot record (each with its round) into one at out: frames
    hard-linked (copied across file systems), rows renumbered, each dataset's laps and source
    logs after the previous ones', every source log tagged with its round. ValueError for no
    parts, an out that holds a dataset, or parts of different maps."""
    if not parts:
        raise ValueError("merge: no datasets to aggregate")
    if (out / dataset.MANIFEST).exists():
        raise ValueError(f"{out}: already holds a dataset ({dataset.MANIFEST})")
    loaded = [(r, dataset.load(p)) for r, p in parts]
    map_names = {str(d.manifest.get("map")) for _, d in loaded}
    if len(map_names) != 1:
        raise ValueError(f"merge: datasets of different maps {sorted(map_names)}")
    (out / dataset.FRAMES_DIR).mkdir(parents=True, exist_ok=True)
    rows: list[dict[str, Any]] = []
    sources: list[dict[str, Any]] = []
    rounds: list[dict[str, Any]] = []
    lap_base = 0
    for round_, d in loaded:
        laps_here = int(d.manifest.get("laps", 0))
        for r in d.rows:
            idx = len(rows)
            name = f"{dataset.FRAMES_DIR}/{idx:06d}.jpg"
            src, dst = d.root / r["file"], out / name
            try:
                os.link(src, dst)
            except OSError:
                shutil.copyfile(src, dst)
            row: dict[str, Any] = {k: r.get(k, "") for k in dataset.COLUMNS}
            row.update(frame=idx, file=name, log=len(sources) + int(r["log"]),
                       lap=lap_base + int(r["lap"]))  # fmt: skip
            laps_here = max(laps_here, int(r["lap"]) + 1)
            rows.append(row)
        for s in d.manifest.get("source_logs", []):
            sources.append(dict(s, round=round_))
        rounds.append({"round": round_, "dataset": str(d.root), "frames": len(d.rows),
                       "laps": laps_here, "first_lap": lap_base})  # fmt: skip
        lap_base += laps_here
    with open(out / dataset.TABLE, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=dataset.COLUMNS)
        w.writeheader()
        w.writerows(rows)
    per_lap: dict[str, int] = {}
    for row in rows:
        per_lap[str(row["lap"])] = per_lap.get(str(row["lap"]), 0) + 1
    first = loaded[0][1].manifest
    manifest: dict[str, Any] = {
        "source_logs": sources,
        "map": map_names.pop(),
        "seed": [d.manifest.get("seed") for _, d in loaded],
        "vehicle": first.get("vehicle"),
        "frame_count": len(rows),
        "laps": lap_base,
        "frames_per_lap": per_lap,
        "label": "the expert's pure pursuit: expert_steering (round 0) and, in the rollouts, "
        "its steering from each frame's pose (dagger.py)",
        "camera": first.get("camera", {}),
        "table": dataset.TABLE,
        "columns": list(dataset.COLUMNS),
        "rounds": rounds,
        "randomisation": {"simulator": [s.get("meta", {}).get("randomisation") for s in sources]},
    }
    (out / dataset.MANIFEST).write_text(json.dumps(manifest, indent=2) + "\n")
    return manifest


def label_rollout(root: Path, lookahead_m: float) -> int:
    """Writes the expert's label beside every frame of a rollout's dataset (steering and
    expert_steering: pure pursuit at lookahead_m from the frame's ground-truth pose, on the lane
    its log's meta names); returns the frame count."""
    from autodrive.learn.pilot import labels  # the pure pursuit of the C library (cffi)

    d = dataset.load(root)
    steer = labels.relabel(d.rows, d.manifest, lookahead_m)
    for r, s in zip(d.rows, steer):
        r["steering"] = r["expert_steering"] = f"{float(s):.5f}"
    with open(root / dataset.TABLE, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=dataset.COLUMNS)
        w.writeheader()
        w.writerows(d.rows)
    d.manifest["label"] = f"the expert's pure pursuit at {lookahead_m:g} m from each frame's pose"
    (root / dataset.MANIFEST).write_text(json.dumps(d.manifest, indent=2) + "\n")
    return len(d.rows)


def log(msg: str) -> None:
    print(f"pilot dagger: {msg}", file=sys.stderr, flush=True)


def _train(cfg: DaggerConfig, data: Path, out: Path, round_: int) -> dict[str, Any]:
    from autodrive.learn.pilot.train import TrainConfig, train

    tcfg = TrainConfig(
        epochs=cfg.epochs, seed=cfg.train_seed, name=cfg.name, threads=cfg.threads,
        samples_per_epoch=cfg.samples_per_epoch, randomise=cfg.randomise,
        balance_max_ratio=cfg.balance_max_ratio,
    )  # fmt: skip
    log(f"round {round_}: training on {data}")
    rep = train(data, out, tcfg)
    # the camera noise the cloning mission's conditions take as the training's (normal: it,
    # noise2x: twice it): the shipped recipe's 2.0, whatever the randomised recordings drew
    side = out / f"{cfg.name}.json"
    doc = json.loads(side.read_text())
    doc["trained"]["camera_noise"] = EVAL_CAMERA_NOISE
    side.write_text(json.dumps(doc, indent=2) + "\n")
    return rep


def _rollout(cfg: DaggerConfig, model: Path, work: Path, build: Path, round_: int,
             rand: dict[str, float], lcm_url: str) -> tuple[Path, dict[str, Any]]:  # fmt: skip
    from autodrive.hil.missions import cloning
    from autodrive.learn.pilot.expert import default_url

    seed = rollout_seed(cfg.seed, round_)
    style = road_styles.draw(seed) if cfg.road_styles else None
    tex = road_styles.write_texture_dir(cloning.MAP, style, work / "road") if style else None
    out = work / "rollout"
    logf = work / "rollout.lcmlog"
    args = argparse.Namespace(
        mission="cloning", build=str(build), out=str(out), seed=seed, headless=True,
        timeout=ROLLOUT_TIMEOUT_S, laps=cfg.rollout_laps, condition="normal", model=str(model),
        save_frames=0, start_m=cloning.START_ALONG_M, distance_m=0.0,
        lcm_url=lcm_url or default_url(0),
        takeover_margin_m=cfg.takeover_margin_m, log=logf,
        light_level=rand.get("light_level"), camera_noise=rand.get("camera_noise"),
        camera_blur=rand.get("camera_blur"), texture_dir=tex,
    )  # fmt: skip
    log(f"round {round_}: rollout of {model} on seed {seed} ({json.dumps(rand)})")
    code = cloning.run(args, console=sys.stderr)
    rep: dict[str, Any] = json.loads((out / "report.json").read_text())
    rep["exit_code"] = code
    fps = cloning.trained(model, "camera_fps", cloning.DEFAULT_TRAINED_FPS)
    noise = rand.get("camera_noise") or cloning.trained(
        model, "camera_noise", cloning.DEFAULT_TRAINED_NOISE
    )
    meta = {
        "source": "dagger", "round": round_, "map": cloning.MAP, "route": cloning.TRAINED_ROUTE,
        "lane_shift": 0, "laps": cfg.rollout_laps, "seed": seed,
        "lookahead_m": ExpertRun.lookahead_m, "camera_fps": fps, "camera_noise": noise,
        "light_level": rand.get("light_level", 1.0), "camera_blur": rand.get("camera_blur", 0.0),
        "takeover_margin_m": cfg.takeover_margin_m, "model": str(model),
        "model_sha256": sha256_file(model), "randomisation": rand or None,
        "speed": None, "perturb": 0.0,
        "road_style": road_styles.as_record(style) if style else None,
    }  # fmt: skip
    meta_path(logf).write_text(json.dumps(meta, indent=2) + "\n")
    return logf, rep


def run_dagger(
    cfg: DaggerConfig,
    out: Path,
    work: Path,
    build: Path,
    logs: list[Path] | None = None,
    lcm_url: str = "",
) -> dict[str, Any]:
    """Runs round 0 and cfg.rounds DAgger rounds; writes the last model (NAME.onnx + .json) and
    the report (dagger_report.json, .md) into out, everything else into work. The rollouts run
    on lcm_url, by default a multicast port of this process's own (expert.default_url): on the
    instance's shared bus another cloning run's ground truth and SIM_TELEPORT would mix with
    the rollout's (seen: two referees resetting one car, and both cars' frames in the log)."""
    cfg.check()
    if (work / "round0").exists():
        raise FileExistsError(f"{work}: holds an earlier run (round0/): give a new --work")
    from autodrive.learn.pilot.expert import default_url, record_expert

    sim_random = SimRandom()
    t0, cpu0 = time.monotonic(), cpu_s()
    rounds: list[dict[str, Any]] = []
    # round 0: the expert's laps, S with laps - 1 and S + 1 with 1 (two recordings: the
    # validation lap a recording of its own seed)
    r0 = work / "round0"
    r0.mkdir(parents=True)
    tc, cc = time.monotonic(), cpu_s()
    if logs is None:
        logs = []
        for k, laps in enumerate((cfg.expert_laps - 1, 1)):
            s = cfg.seed + k
            rand = sim_random.draw(s) if cfg.randomise else {}
            run = ExpertRun(
                laps=laps, seed=s, camera_noise=rand.get("camera_noise", 2.0),
                light_level=rand.get("light_level", 1.0), camera_blur=rand.get("camera_blur", 0.0),
                road_style=road_styles.draw(s) if cfg.road_styles else None,
            )  # fmt: skip
            logf = r0 / f"expert_seed{s}.lcmlog"
            log(f"round 0: the expert, {laps} lap(s) on seed {s} ({json.dumps(rand)})")
            record_expert(run, logf, build, default_url(k))
            meta = json.loads(meta_path(logf).read_text())
            meta["randomisation"] = rand or None
            meta_path(logf).write_text(json.dumps(meta, indent=2) + "\n")
            logs.append(logf)
    record_s = (time.monotonic() - tc, cpu_s() - cc)
    dataset.record(logs, r0 / "dataset", build=build, progress=False)
    parts = [(0, r0 / "dataset")]
    data = r0 / "aggregate"
    merge(parts, data)
    tt, ct = time.monotonic(), cpu_s()
    rep = _train(cfg, data, r0 / "model", 0)
    model = r0 / "model" / f"{cfg.name}.onnx"
    rounds.append({
        "round": 0, "rollout": None, "frames_added": dataset.load(r0 / "dataset").manifest["frame_count"],
        "frames_total": rep["frames"], "val_rmse": rep["val_rmse"],
        "record_wall_s": round(record_s[0], 1), "record_cpu_s": round(record_s[1], 1),
        "train_wall_s": round(time.monotonic() - tt, 1), "train_cpu_s": round(cpu_s() - ct, 1),
        "model_sha256": sha256_file(model),
    })  # fmt: skip
    for r in range(1, cfg.rounds + 1):
        wr = work / f"round{r}"
        wr.mkdir(parents=True)
        rand = sim_random.draw(rollout_seed(cfg.seed, r)) if cfg.randomise else {}
        tr, cr = time.monotonic(), cpu_s()
        logf, roll = _rollout(cfg, model, wr, build, r, rand, lcm_url)
        roll_s = (time.monotonic() - tr, cpu_s() - cr)
        score = round_score(roll, cfg.rollout_laps)
        log(f"round {r}: rollout of round {r - 1}'s model: {json.dumps(score)}")
        dataset.record([logf], wr / "dataset", build=build, progress=False)
        added = label_rollout(wr / "dataset", ExpertRun.lookahead_m)
        parts.append((r, wr / "dataset"))
        data = wr / "aggregate"
        merge(parts, data)
        tt, ct = time.monotonic(), cpu_s()
        rep = _train(cfg, data, wr / "model", r)
        model = wr / "model" / f"{cfg.name}.onnx"
        rounds.append({
            "round": r, "rollout": dict(score, model_of_round=r - 1, seed=rollout_seed(cfg.seed, r),
                                        randomisation=rand or None, exit_code=roll["exit_code"]),
            "frames_added": added, "frames_total": rep["frames"], "val_rmse": rep["val_rmse"],
            "rollout_wall_s": round(roll_s[0], 1), "rollout_cpu_s": round(roll_s[1], 1),
            "train_wall_s": round(time.monotonic() - tt, 1), "train_cpu_s": round(cpu_s() - ct, 1),
            "model_sha256": sha256_file(model),
        })  # fmt: skip
        # the rounds so far, should a later one fail or be stopped
        (work / f"{REPORT}_partial.json").write_text(json.dumps(rounds, indent=2) + "\n")
    out.mkdir(parents=True, exist_ok=True)
    last = model.parent
    for suffix in (".onnx", ".json"):
        shutil.copyfile(last / f"{cfg.name}{suffix}", out / f"{cfg.name}{suffix}")
    report: dict[str, Any] = {
        "config": asdict(cfg),
        "sim_randomisation": asdict(sim_random) if cfg.randomise else None,
        "expert_logs": [str(p) for p in logs],
        "rounds": rounds,
        "model": str(out / f"{cfg.name}.onnx"),
        "model_sha256": sha256_file(out / f"{cfg.name}.onnx"),
        "wall_s": round(time.monotonic() - t0, 1),
        "cpu_s": round(cpu_s() - cpu0, 1),
        "load_avg_end": round(os.getloadavg()[0], 1),
        "command": "tools/pilot dagger " + command_line(cfg, out, work, logs),
    }
    (out / f"{REPORT}.json").write_text(json.dumps(report, indent=2) + "\n")
    (out / f"{REPORT}.md").write_text(report_md(report))
    log(f"done in {report['wall_s']:.0f} s wall, {report['cpu_s']:.0f} s CPU: {report['model']}")
    return report


def command_line(cfg: DaggerConfig, out: Path, work: Path, logs: list[Path] | None) -> str:
    d = DaggerConfig()
    parts = [f"--out {out}", f"--work {work}"]
    for key, flag in (("rounds", "--rounds"), ("seed", "--seed"), ("expert_laps", "--expert-laps"),
                      ("rollout_laps", "--rollout-laps"), ("epochs", "--epochs"),
                      ("samples_per_epoch", "--samples-per-epoch"), ("train_seed", "--train-seed"),
                      ("takeover_margin_m", "--takeover-margin"), ("name", "--name"),
                      ("balance_max_ratio", "--balance-max-ratio")):  # fmt: skip
        if getattr(cfg, key) != getattr(d, key):
            parts.append(f"{flag} {getattr(cfg, key)}")
    if not cfg.randomise:
        parts.append("--no-randomise")
    if cfg.road_styles:
        parts.append("--road-styles")
    if logs and all(p.parent != work / "round0" for p in logs):
        parts.append("--logs " + " ".join(map(str, logs)))
    return " ".join(parts)


def report_md(r: dict[str, Any]) -> str:
    c = r["config"]
    lines = [
        f"# DAgger report: {c['name']}",
        "",
        f"`{r['command']}`: {c['rounds']} rounds after round 0, seed {c['seed']} (rollouts on "
        f"seed + {ROLLOUT_SEED_OFFSET} + round), {c['rollout_laps']} lap(s) a rollout, takeover "
        f"margin {c['takeover_margin_m']} m, {c['epochs']} epochs of {c['samples_per_epoch']} "
        f"draws, train seed {c['train_seed']}, balance max ratio "
        f"{c.get('balance_max_ratio', augment.DEFAULT_MAX_RATIO)}, randomisation {'on' if c['randomise'] else 'off'}, "
        f"road styles {'on' if c.get('road_styles') else 'off'}.",
        f"Whole run: {r['wall_s']:.0f} s wall, {r['cpu_s']:.0f} s CPU (load {r['load_avg_end']} "
        "at the end; the machine is shared: the wall time includes other jobs').",
        "",
        "Autonomy of round r's rollout is the model of round r - 1 driving, scored honestly: "
        "laps completed or 0, each takeover and stall an intervention.",
        "",
        "| round | model driving | autonomy % | laps | interventions (takeovers, stalls) | "
        "cross-track RMS [m] | frames added / total | val RMSE | CPU rollout + train [s] |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for rd in r["rounds"]:
        ro = rd["rollout"]
        if ro is None:
            lines.append(
                f"| 0 | (the expert's laps) | - | - | - | - | {rd['frames_added']} / "
                f"{rd['frames_total']} | {rd['val_rmse']} | {rd['record_cpu_s']} + "
                f"{rd['train_cpu_s']} |"
            )
            continue
        lines.append(
            f"| {rd['round']} | round {ro['model_of_round']} | {ro['autonomy_pct']}"
            f"{'' if ro['completed'] else ' (laps not completed)'} | {ro['laps']} | "
            f"{ro['interventions']} ({ro['takeovers']}, {ro['stalls']}) | "
            f"{ro['cross_track_rms_m']} | {rd['frames_added']} / {rd['frames_total']} | "
            f"{rd['val_rmse']} | {rd['rollout_cpu_s']} + {rd['train_cpu_s']} |"
        )
    lines += ["", f"Model: `{r['model']}` (sha256 {r['model_sha256'][:12]}...)", ""]
    return "\n".join(lines)
