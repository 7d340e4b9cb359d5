"""`tools/pilot`: behavioural cloning (issue 16): expert, record, train, analyse, make-model.
Run `tools/pilot COMMAND --help` for each command's options."""

from __future__ import annotations

import argparse
from dataclasses import replace
import os
import sys
from pathlib import Path

from autodrive.core import seeds
from autodrive.core.cli_numbers import comma_floats
from autodrive.maps import road_styles
from autodrive.core.settings import RELEASE_BUILD
from autodrive.learn.pilot.dagger import ROLLOUT_SEED_OFFSET, TAKEOVER_MARGIN_M, DaggerConfig
from autodrive.learn.pilot.expert import ExpertRun

DESCRIPTION = """Behavioural cloning of the lane-keeping expert from the front camera.
  expert      drive N laps with the simulator's expert (pure pursuit + perturbations), record an LCM log
  record      LCM log(s) -> dataset (JPEG frames, frames.csv, manifest.json)
  train       dataset -> NAME.onnx + NAME.json sidecar, loss curves, report
  analyse     activation maps, VisualBackProp saliency and a lap of predictions vs the expert
  make-model  expert 5 laps + record + train + analyse: the shipped models/pilot/driving_school
  dagger      DAgger: the model drives in HIL, the expert labels every frame (and takes over
              near the lane bound), the rounds' data aggregated and trained on, N rounds
A person can drive instead of the expert: autodrive-sim --map driving_school --cameras
--lockstep-client, the runtime on its pty, autodrive-teleop, and tools/record LOG; then
`tools/pilot record LOG --map driving_school` (docs/guides/training.md)."""


def _build() -> Path:
    return Path(os.environ.get("AUTODRIVE_BUILD", str(RELEASE_BUILD)))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        prog="tools/pilot", description=DESCRIPTION, formatter_class=argparse.RawTextHelpFormatter
    )
    sub = ap.add_subparsers(dest="cmd", required=True, metavar="COMMAND")

    e = sub.add_parser("expert", help="record the expert driving laps (LCM log + LOG.meta.json)")
    e.add_argument("--out", type=Path, required=True, help="the LCM log to write")
    e.add_argument("--map", default="driving_school")
    e.add_argument(
        "--route", default="loop_ccw",
        help="a route of the map: a loop is driven --laps times, any other once (Driving "
        "School's south_to_north and west_to_north: its junctions' 0.46 m right turns)",
    )  # fmt: skip
    e.add_argument(
        "--lane-shift", type=int, default=0,
        help="drive the lane this many lane widths left of the route's, in its direction "
        "(1 on Driving School's loop_ccw: the inner lane, counter-clockwise)",
    )  # fmt: skip
    e.add_argument("--laps", type=int, default=5)
    e.add_argument(
        "--seed", type=int, default=seeds.CLONING_EXPERT_SEED,
        help="perturbations and camera noise (a training seed, autodrive.core.seeds)",
    )  # fmt: skip
    e.add_argument("--speed", type=float, default=0.8, help="throttle, fraction of top speed")
    e.add_argument("--perturb", type=float, default=0.35, help="perturbation amplitude (0..1)")
    e.add_argument(
        "--camera-fps", type=float, default=ExpertRun.camera_fps, help="[Hz] of sim time"
    )
    e.add_argument("--camera-noise", type=float, default=2.0, help="sigma [8-bit levels]")
    e.add_argument("--light-level", type=float, default=1.0, help="0..1 (1: day)")
    e.add_argument("--camera-blur", type=float, default=0.0, help="Gaussian sigma [px]")
    e.add_argument(
        "--road-style", choices=("kit", "random"), default="kit",
        help="kit: the map's own lines and asphalt; random: the lines' colours, dashes and the "
        "asphalt's tone drawn from --seed (domain randomisation, autodrive.maps.road_styles)",
    )  # fmt: skip
    e.add_argument(
        "--light-rgb",
        default="",
        metavar="R,G,B",
        help="the lights' gain per channel, 0.5..1.5 (autodrive-sim --light-rgb)",
    )
    e.add_argument(
        "--camera-exposure",
        type=float,
        default=0.0,
        metavar="EV",
        help="[EV] the frames x 2^EV, clipped (-2..2)",
    )
    e.add_argument(
        "--camera-jitter",
        default="",
        metavar="MM,DEG",
        help="the camera mount moved up to +-MM [mm] and turned up to +-DEG [deg] "
        "per axis, drawn from --seed",
    )
    e.add_argument(
        "--distractors",
        type=int,
        default=0,
        metavar="N",
        help="N static cones and boxes beside the road, placed from --seed (0..20)",
    )
    e.add_argument(
        "--duration", type=float, default=0.0,
        help="[s] of sim time: stop there (0: when the laps are done); the run is the same up to it",
    )  # fmt: skip
    e.add_argument("--lcm-url", default="", help="default: a port of this process's own")

    r = sub.add_parser("record", help="extract a dataset from LCM log(s)")
    r.add_argument("logs", nargs="+", type=Path, metavar="LOG")
    r.add_argument("--out", type=Path, required=True, help="the dataset folder")
    r.add_argument("--map", default=None, help="the map (else from LOG.meta.json)")
    r.add_argument("--seed", type=int, default=None, help="the recording's seed (else meta)")
    r.add_argument("--vehicle", default=None, help="default: car 1 (NIGEL1)")

    t = sub.add_parser("train", help="train, export ONNX + sidecar JSON")
    t.add_argument("dataset", type=Path, metavar="DATASET")
    t.add_argument("--out", type=Path, required=True)
    t.add_argument("--name", default="model", help="files NAME.onnx, NAME.json, NAME.pt")
    t.add_argument("--epochs", type=int, default=4)
    t.add_argument("--lr", type=float, default=1e-3)
    t.add_argument("--batch", type=int, default=64)
    t.add_argument("--seed", type=int, default=0)
    t.add_argument("--threads", type=int, default=2, help="PyTorch threads")
    t.add_argument("--max-frames", type=int, default=0, help="use the first N frames (0: all)")
    t.add_argument(
        "--samples-per-epoch", type=int, default=0, help="drawn per epoch (0: training frames)"
    )
    t.add_argument("--stride", type=int, default=1, help="use every N-th frame")
    t.add_argument(
        "--balance-max-ratio", type=float, default=None,
        help="balancing: a frame is drawn at most this many times as often as one of the "
        "commonest steering (default: the shipped recipe's)",
    )  # fmt: skip
    t.add_argument(
        "--channels", type=int, choices=(1, 3), default=1,
        help="input channels the network reads: 1 = the luma of the YUV input (the shipped "
        "recipe: colour would let it tell the centre line from the edge line), 3 = all",
    )  # fmt: skip
    t.add_argument(
        "--label-lookahead", type=float, default=0.0, metavar="M",
        help="label each frame with pure pursuit's steering at this lookahead [m] from its "
        "ground-truth pose (a label the picture determines; docs/guides/training.md) instead of the recorded "
        "steering (0, the default)",
    )  # fmt: skip
    t.add_argument(
        "--randomise", action="store_true",
        help="image-level domain randomisation (augment.Randomise: light colour, exposure, "
        "blur, noise, camera pose jitter, road texture, distractors); off in the shipped recipe",
    )  # fmt: skip
    t.add_argument(
        "--curve-max", type=float, default=0.0, metavar="DK",
        help="an experiment (the shipped recipe: 0): bend the ground of half the drawn frames "
        "by an extra curvature up to +-DK [1/m], the label following (augment.CurveWarp)",
    )  # fmt: skip

    a = sub.add_parser("analyse", help="activation maps, saliency, a lap vs the expert (PNGs)")
    a.add_argument("--model", type=Path, required=True, help="NAME.onnx (NAME.json beside it)")
    a.add_argument("--dataset", type=Path, required=True)
    a.add_argument("--out", type=Path, required=True)
    a.add_argument("--lap", type=int, default=None, help="default: the first validation lap")
    a.add_argument("--samples", type=int, default=3, help="frames with activation maps")

    m = sub.add_parser("make-model", help="expert + record + train + analyse, one command")
    m.add_argument("--out", type=Path, default=Path("models/pilot"), help="the shipped files")
    m.add_argument("--work", type=Path, default=Path("out/pilot"), help="log, dataset, figures")
    m.add_argument("--name", default="driving_school")
    m.add_argument("--laps", type=int, default=5)
    m.add_argument(
        "--seed", type=int, default=seeds.CLONING_EXPERT_SEED,
        help="the recordings' seeds S and S + 1 (training seeds, autodrive.core.seeds)",
    )  # fmt: skip
    m.add_argument("--train-seed", type=int, default=0)
    m.add_argument(
        "--other-lane-laps", type=int, default=0,
        help="an experiment (the shipped model: 0): this many of the laps in the road's other "
        "lane, still counter-clockwise (docs/guides/demo-cloning.md: the reverse direction)",
    )  # fmt: skip
    m.add_argument("--epochs", type=int, default=4)
    m.add_argument(
        "--label-lookahead", type=float, default=0.0, metavar="M",
        help="train on pure pursuit labels at this lookahead [m] (tools/pilot train "
        "--label-lookahead); 0: the expert's recorded steering",
    )  # fmt: skip
    m.add_argument(
        "--curve-max", type=float, default=0.0, metavar="DK",
        help="an experiment (the shipped recipe: 0): bend the ground of half the drawn frames "
        "by an extra curvature up to +-DK [1/m], the label following (augment.CurveWarp)",
    )  # fmt: skip
    m.add_argument(
        "--logs", type=Path, nargs="+", default=None, metavar="LOG",
        help="skip the expert: use these recordings of `tools/pilot expert`, which must be the "
        "recipe's (their LOG.meta.json is checked against --laps and --seed)",
    )  # fmt: skip

    dd = DaggerConfig()
    g = sub.add_parser(
        "dagger", help="DAgger rounds: drive the model in HIL, the expert labels, retrain",
        description="DAgger (docs/guides/training.md): round 0 trains on the expert's laps; "
        "each round then drives the last model in HIL on the trained route (the cloning "
        "mission, sim clock, lockstep) with every frame recorded and labelled by the expert's "
        "pure pursuit from its pose, the expert taking over (the car put back on the centre "
        "line) where a wheel comes within --takeover-margin of the lane bound; the rounds' data "
        "aggregated, retrained. Writes OUT/NAME.onnx + .json and OUT/dagger_report.{json,md} "
        "(autonomy per round).",
    )  # fmt: skip
    g.add_argument("--rounds", type=int, default=dd.rounds, help="rounds after round 0 (>= 0)")
    g.add_argument(
        "--seed", type=int, default=dd.seed,
        help="the expert's recordings on S and S + 1, round r's rollout on S + "
        f"{ROLLOUT_SEED_OFFSET} + r (training seeds, autodrive.core.seeds)",
    )  # fmt: skip
    g.add_argument("--out", type=Path, default=Path("out/pilot-dagger/model"))
    g.add_argument("--work", type=Path, default=Path("out/pilot-dagger/work"),
                   help="logs, datasets and each round's model (must not hold a run)")  # fmt: skip
    g.add_argument("--name", default=dd.name)
    g.add_argument("--expert-laps", type=int, default=dd.expert_laps, help="round 0's laps")
    g.add_argument("--rollout-laps", type=int, default=dd.rollout_laps, help="laps a rollout")
    g.add_argument("--epochs", type=int, default=dd.epochs)
    g.add_argument("--samples-per-epoch", type=int, default=dd.samples_per_epoch)
    g.add_argument("--train-seed", type=int, default=dd.train_seed)
    g.add_argument(
        "--takeover-margin", type=float, default=TAKEOVER_MARGIN_M, metavar="M",
        help="[m] the expert takes over where a wheel's outer edge comes this near the lane "
        f"bound (default {TAKEOVER_MARGIN_M})",
    )  # fmt: skip
    g.add_argument("--no-randomise", action="store_true",
                   help="no domain randomisation (simulator or image level)")  # fmt: skip
    g.add_argument(
        "--road-styles", action="store_true",
        help="each recording's and rollout's road markings drawn from its seed (centre and "
        "edge lines' colour and dashing, the asphalt's tone: autodrive.maps.road_styles)",
    )  # fmt: skip
    g.add_argument(
        "--balance-max-ratio", type=float, default=dd.balance_max_ratio, metavar="R",
        help="training's balancing (tools/pilot train --balance-max-ratio; default "
        f"{dd.balance_max_ratio:g})",
    )  # fmt: skip
    g.add_argument("--threads", type=int, default=dd.threads, help="PyTorch threads")
    g.add_argument(
        "--logs", type=Path, nargs="+", default=None, metavar="LOG",
        help="round 0's expert recordings (tools/pilot expert) instead of recording them",
    )  # fmt: skip
    g.add_argument("--lcm-url", default="", help="the rollouts' bus (default: a port of its own)")

    args = ap.parse_args(argv)
    try:
        return _run(args)
    except KeyboardInterrupt:
        print("tools/pilot: interrupted", file=sys.stderr)
        return 130
    except (ValueError, FileNotFoundError, FileExistsError, RuntimeError) as err:
        print(f"tools/pilot {args.cmd}: {err}", file=sys.stderr)
        return 1


def _run(args: argparse.Namespace) -> int:
    if args.cmd == "expert":
        from autodrive.learn.pilot.expert import record_expert

        run = ExpertRun(
            map=args.map, route=args.route, lane_shift=args.lane_shift, laps=args.laps,
            seed=args.seed, speed=args.speed,
            perturb=args.perturb, camera_fps=args.camera_fps, camera_noise=args.camera_noise,
            light_level=args.light_level, duration_s=args.duration, camera_blur=args.camera_blur,
            road_style=road_styles.draw(args.seed) if args.road_style == "random" else None,
            light_rgb=comma_floats(args.light_rgb, 3, "R,G,B", "--light-rgb") if args.light_rgb else None,
            camera_exposure_ev=args.camera_exposure,
            camera_jitter=comma_floats(args.camera_jitter, 2, "MM,DEG", "--camera-jitter") if args.camera_jitter else None,
            distractors=args.distractors,
        )  # fmt: skip
        wall = record_expert(run, args.out, _build(), args.lcm_url)
        print(f"pilot expert: {args.out} in {wall:.0f} s wall")
        return 0
    if args.cmd == "record":
        from autodrive.learn.pilot.dataset import record

        record(args.logs, args.out, args.map, args.seed, args.vehicle, _build())
        return 0
    if args.cmd == "train":
        from autodrive.learn.pilot.train import TrainConfig, train

        cfg = TrainConfig(
            epochs=args.epochs, lr=args.lr, batch=args.batch, seed=args.seed, name=args.name,
            threads=args.threads, max_frames=args.max_frames,
            samples_per_epoch=args.samples_per_epoch, stride=args.stride,
            channels=args.channels, label_lookahead_m=args.label_lookahead,
            curve_max_dk=args.curve_max, randomise=args.randomise,
        )  # fmt: skip
        if args.balance_max_ratio is not None:
            cfg = replace(cfg, balance_max_ratio=args.balance_max_ratio)
        train(args.dataset, args.out, cfg)
        return 0
    if args.cmd == "analyse":
        from autodrive.learn.pilot.analyse import analyse

        analyse(args.model, args.dataset, args.out, args.lap, args.samples)
        return 0
    if args.cmd == "dagger":
        from autodrive.learn.pilot.dagger import run_dagger

        dcfg = DaggerConfig(
            rounds=args.rounds, seed=args.seed, expert_laps=args.expert_laps,
            rollout_laps=args.rollout_laps, epochs=args.epochs,
            samples_per_epoch=args.samples_per_epoch, train_seed=args.train_seed,
            takeover_margin_m=args.takeover_margin, randomise=not args.no_randomise,
            road_styles=args.road_styles, threads=args.threads, name=args.name,
            balance_max_ratio=args.balance_max_ratio,
        )  # fmt: skip
        run_dagger(dcfg, args.out, args.work, _build(), args.logs, args.lcm_url)
        return 0
    from autodrive.learn.pilot.make_model import make_model

    make_model(
        args.out, args.work, args.name, args.laps, args.seed, args.train_seed, args.epochs,
        _build(), args.logs, args.other_lane_laps, args.label_lookahead, args.curve_max,
    )  # fmt: skip
    return 0
