"""tools/marl {train,eval}: train the shared intersection policy with PPO, and evaluate a policy
(with and without the shield) and the rule-based baseline on seeded held-out episodes."""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path
from typing import Any

from autodrive.core import seeds
from autodrive.core.settings import settings
from autodrive.learn.marl.env import SHAPINGS, STEER_RATE_PENALTY

DEFAULT_MODEL = settings().models_dir / "marl" / "intersection.onnx"
# tools/marl eval's default first seed, a development one (what a user looks at); the bench's
# figures come from seeds.EVALUATION, training's seeds stay in seeds.TRAINING
HELD_OUT_SEED = seeds.DEVELOPMENT.start


def log(msg: str) -> None:
    print(f"[marl] {msg}", file=sys.stderr, flush=True)


def parse_stages(text: str) -> list[tuple[int, int]]:
    """ "1:40000,4:200000" -> [(1, 40000), (4, 200000)]."""
    out = []
    for part in text.split(","):
        try:
            cars, steps = (int(x) for x in part.split(":"))
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"--stages '{text}': expected cars:steps[,cars:steps...], e.g. 1:40000,4:200000"
            ) from None
        if not 1 <= cars <= 4 or steps < 1:
            raise argparse.ArgumentTypeError(f"--stages '{part}': cars 1..4, steps >= 1")
        out.append((cars, steps))
    return out


def cmd_train(a: argparse.Namespace) -> int:
    from autodrive.learn.marl.train import TrainConfig, train, write_results

    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    pool = None
    if a.address:
        from autodrive.learn.sweep.jobs import close_pool, open_pool

        try:
            pool = open_pool(a.workers, a.address)
        except (ValueError, RuntimeError) as e:
            log(str(e))
            return 2
        log(f"rollouts on {pool.describe()}, {a.workers} actor(s)")
    cfg = TrainConfig(
        a.stages,
        a.action_mode,
        a.copies,
        a.workers,
        a.seed,
        max_wall_s=60.0 * a.max_wall_min,
        shield=a.shield,
        ray_address=a.address,
        shaping=a.shaping,
        steer_rate_penalty=a.steer_rate_penalty,
        validate_episodes=a.validate_episodes,
        validate_from=a.validate_from,
        validate_every=a.validate_every,
        validate_workers=a.workers,
    )
    try:
        model, curve, info = train(cfg, log, out)
    finally:
        if pool is not None:
            close_pool(pool)
    info["command"] = " ".join(["tools/marl"] + sys.argv[1:])
    sidecar = write_results(model, curve, info, Path(a.onnx), out, a.action_mode)
    log(f"wrote {a.onnx}, {sidecar}, {out / 'learning_curve.png'}, {out / 'train_report.json'}")
    print(json.dumps({"wall_s": info["wall_s"], "onnx": str(a.onnx)}))
    return 0


def cmd_eval(a: argparse.Namespace) -> int:
    from autodrive.learn.marl.evaluate import evaluate_all

    report = evaluate_all(
        Path(a.model), a.episodes, a.cars, a.seed, a.modes.split(","), log, a.workers
    )
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "eval_report.json").write_text(json.dumps(report, indent=2) + "\n")
    log(f"wrote {out / 'eval_report.json'}")
    print(json.dumps(report))
    return 0


def parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="tools/marl", description=__doc__)
    sub = p.add_subparsers(dest="cmd", required=True)
    t = sub.add_parser("train", help="PPO with a shared policy; writes ONNX + JSON + curves")
    t.add_argument(
        "--stages",
        type=parse_stages,
        default=parse_stages("1:30000,4:250000"),
        help="curriculum cars:agent_steps,... (default 1:30000,4:250000)",
    )
    t.add_argument(
        "--action-mode", default="discrete", choices=("discrete", "discrete_throttle", "continuous")
    )
    t.add_argument(
        "--shield",
        action="store_true",
        help="train with the time-to-collision shield in the loop (as deployed)",
    )
    t.add_argument(
        "--shaping",
        default="progress",
        choices=SHAPINGS,
        help="shaping reward: progress (0.3 x m gained towards the goal, default) or paper "
        "(0.01 / (0.001 + distance) per step, which pays waiting near the goal)",
    )
    t.add_argument(
        "--steer-rate-penalty",
        type=float,
        default=STEER_RATE_PENALTY,
        help="continuous action mode: reward lost per unit of normalised steering change per "
        f"0.1 s step (default {STEER_RATE_PENALTY})",
    )
    t.add_argument(
        "--validate-episodes",
        type=int,
        default=0,
        help="checkpoint selection: validation episodes per checkpoint (seeds from 5e8, "
        "disjoint from training and held-out seeds; 0: keep the last weights)",
    )
    t.add_argument(
        "--validate-from",
        type=int,
        default=0,
        help="checkpoint selection: first checkpoint after this many agent steps (all stages)",
    )
    t.add_argument(
        "--validate-every",
        type=int,
        default=50_000,
        help="checkpoint selection: agent steps between checkpoints (and one at the end)",
    )
    t.add_argument("--copies", type=int, default=2, help="environment copies (each N cars)")
    t.add_argument("--workers", type=int, default=2, help="rollout processes (1: in process)")
    t.add_argument("--seed", type=int, default=0)
    t.add_argument(
        "--max-wall-min",
        type=float,
        default=float("inf"),
        help="stop after this wall time [min] and keep the model",
    )
    t.add_argument(
        "--address",
        default="",
        help="HOST:PORT of a Ray cluster (`ray start --head`): rollouts on its actors, one per worker",
    )
    t.add_argument("--onnx", default=str(DEFAULT_MODEL), help="where the policy goes")
    t.add_argument("--out", default=str(settings().out_dir / "marl-train"))
    t.set_defaults(func=cmd_train)
    e = sub.add_parser("eval", help="seeded held-out episodes: policy +-shield and baseline")
    e.add_argument("--model", default=str(DEFAULT_MODEL))
    e.add_argument("--episodes", type=int, default=50)
    e.add_argument("--cars", type=int, default=4)
    e.add_argument("--seed", type=int, default=HELD_OUT_SEED, help="first held-out seed")
    e.add_argument(
        "--modes",
        default="shield,no_shield,baseline",
        help="comma list of shield, no_shield, baseline",
    )
    e.add_argument("--workers", type=int, default=1, help="processes for the episodes")
    e.add_argument("--out", default=str(settings().out_dir / "marl-eval"))
    e.set_defaults(func=cmd_eval)
    return p


def main(argv: list[str] | None = None) -> int:
    a = parser().parse_args(argv)
    t0 = time.monotonic()
    rc: int = a.func(a)
    log(f"done in {time.monotonic() - t0:.0f} s")
    return rc
