"""tools/sweep eval / rollouts: Gymnasium episodes as independent jobs on Ray
(autodrive.learn.sweep.jobs). A job is a function JOB(env_id, seed, policy, **options) -> dict,
named "module:function" so that any node imports it itself; by default `episode` (one episode:
its return and length) for eval and `rollout` (STEPS transitions, arrays) for rollouts.

A policy is None (actions drawn from the action space, seeded), a stable-baselines3 .zip
(--algo, default PPO; deterministic actions) or "module:function", a scripted policy
function(observation) -> action. --register MODULE imports a module on each node before
gymnasium.make, for environments registered there (the simulator's learning environments).
The same seeds give the same figures wherever they ran: the env is reset with the job's seed
and the policy is deterministic."""

from __future__ import annotations

import argparse
import importlib
import json
import statistics
import sys
import tempfile
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from autodrive.learn.sweep import jobs as sweep_ray
from autodrive.core.settings import OUT_DIR

DEFAULT_EPISODE_JOB = "autodrive.learn.sweep.episodes:episode"
DEFAULT_ROLLOUT_JOB = "autodrive.learn.sweep.episodes:rollout"
MAX_EPISODE_STEPS = 100_000  # a backstop for environments without a time limit

Policy = Callable[[Any], Any]


def log(msg: str) -> None:
    print(msg, file=sys.stderr, flush=True)


def resolve(name: str, what: str) -> Any:
    """The attribute "module:attr"; ValueError naming `what` when it cannot be imported."""
    module, sep, attr = name.partition(":")
    if not sep or not module or not attr:
        raise ValueError(f"{what} {name}: want module:function")
    try:
        return getattr(importlib.import_module(module), attr)
    except (ImportError, AttributeError) as e:
        raise ValueError(f"{what} {name}: {e}") from None


def cartpole_balance(obs: Any) -> int:
    """A scripted CartPole policy: push the cart under the pole (its angle [rad] and angular
    rate [rad/s] weighted), which balances it for hundreds of steps."""
    return 1 if float(obs[2]) + 0.5 * float(obs[3]) > 0.0 else 0


def make_policy(env: Any, seed: int, policy: str | None, algo: str = "PPO") -> Policy:
    """The policy of the option (see the module doc)."""
    if policy is None:
        env.action_space.seed(seed)
        return lambda _obs: env.action_space.sample()
    if policy.endswith(".zip"):
        import stable_baselines3

        cls = getattr(stable_baselines3, algo, None)
        if cls is None:
            raise ValueError(f"--algo {algo}: stable-baselines3 has no such algorithm")
        model = cls.load(policy, device="cpu")
        return lambda obs: model.predict(obs, deterministic=True)[0]
    fn: Policy = resolve(policy, "--policy")
    return fn


def _modules_for(env_id: str, register: tuple[str, ...] | list[str]) -> list[str]:
    """The modules to import before gymnasium.make(env_id): --register's, and autodrive.gym for
    the package's own ids (autodrive/<Name>-v0, registered when it is imported)."""
    own = ["autodrive.gym"] if env_id.startswith("autodrive/") else []
    return own + list(register)


def _make_env(env_id: str, register: tuple[str, ...]) -> Any:
    import gymnasium

    for module in _modules_for(env_id, register):
        importlib.import_module(module)
    return gymnasium.make(env_id)


def episode(
    env_id: str, seed: int, policy: str | None, algo: str = "PPO", register: tuple[str, ...] = ()
) -> dict[str, Any]:
    """One episode reset with `seed`: {seed, return, length, terminated, truncated}."""
    env = _make_env(env_id, register)
    try:
        act = make_policy(env, seed, policy, algo)
        obs, _ = env.reset(seed=seed)
        total, steps, terminated, truncated = 0.0, 0, False, False
        while not (terminated or truncated) and steps < MAX_EPISODE_STEPS:
            obs, reward, terminated, truncated, _ = env.step(act(obs))
            total += float(reward)
            steps += 1
    finally:
        env.close()
    return {
        "seed": seed,
        "return": total,
        "length": steps,
        "terminated": bool(terminated),
        "truncated": bool(truncated),
    }


def rollout(
    env_id: str,
    seed: int,
    policy: str | None,
    algo: str = "PPO",
    register: tuple[str, ...] = (),
    steps: int = 256,
) -> dict[str, Any]:
    """`steps` transitions from a reset with `seed` (reset again, seed + k, after the k-th
    episode ends): arrays obs, actions, rewards, dones, and the finished episodes' returns."""
    env = _make_env(env_id, register)
    obs_l, act_l, rew_l, done_l, returns = [], [], [], [], []
    try:
        act = make_policy(env, seed, policy, algo)
        obs, _ = env.reset(seed=seed)
        ep_return, resets = 0.0, 0
        for _ in range(steps):
            a = act(obs)
            nxt, reward, terminated, truncated, _ = env.step(a)
            obs_l.append(np.asarray(obs))
            act_l.append(np.asarray(a))
            rew_l.append(float(reward))
            done_l.append(bool(terminated or truncated))
            ep_return += float(reward)
            obs = nxt
            if terminated or truncated:
                returns.append(ep_return)
                ep_return, resets = 0.0, resets + 1
                obs, _ = env.reset(seed=seed + resets)
    finally:
        env.close()
    return {
        "seed": seed,
        "obs": np.stack(obs_l),
        "actions": np.stack(act_l),
        "rewards": np.asarray(rew_l, dtype=np.float64),
        "dones": np.asarray(done_l, dtype=bool),
        "episode_returns": returns,
    }


@dataclass(frozen=True)
class LearnJob:
    """One job as it travels to a node: the function's name and its arguments."""

    job: str
    env_id: str
    seed: int
    policy: str | None
    algo: str
    register: tuple[str, ...]
    options: dict[str, Any] = field(default_factory=dict)
    policy_zip: bytes | None = None  # a .zip policy travels with the job: nodes need no copy


def run_learn_job(spec: LearnJob) -> dict[str, Any]:
    fn = resolve(spec.job, "--job")
    with tempfile.TemporaryDirectory(prefix="autodrive-sweep-policy-") as tmp:
        policy = spec.policy
        if spec.policy_zip is not None:
            policy = str(Path(tmp) / "policy.zip")
            Path(policy).write_bytes(spec.policy_zip)
        result: dict[str, Any] = fn(
            spec.env_id, spec.seed, policy, algo=spec.algo, register=spec.register, **spec.options
        )
    return result


def parse_args(kind: str, argv: list[str]) -> argparse.Namespace:
    default_job = DEFAULT_EPISODE_JOB if kind == "eval" else DEFAULT_ROLLOUT_JOB
    what = (
        "the evaluation episodes of a policy (one episode per seed: return, length)"
        if kind == "eval"
        else "the rollouts of a training run (STEPS transitions per seed, as arrays)"
    )
    p = argparse.ArgumentParser(
        prog=f"tools/sweep {kind}",
        description=f"Run {what} of a Gymnasium environment as independent jobs on Ray "
        "(embedded and local by default; --address joins a cluster; --serial: no Ray). "
        f"Writes OUT/{kind}.json"
        + (" and OUT/eval.png" if kind == "eval" else " and OUT/rollouts.npz")
        + "; the last stdout line is the summary JSON. Exit 0 ok, 2 bad input.",
        epilog=f"example: tools/sweep {kind} --env CartPole-v1 --seeds 8 --workers 2 "
        "--policy autodrive.learn.sweep.episodes:cartpole_balance",
    )
    p.add_argument("--env", required=True, help="Gymnasium environment id, e.g. CartPole-v1")
    p.add_argument("--seeds", type=int, default=8, help="number of seeds / jobs (default 8)")
    p.add_argument("--first-seed", type=int, default=1, help="first seed (default 1)")
    p.add_argument(
        "--policy",
        default=None,
        help="a stable-baselines3 .zip, or module:function (a scripted policy obs -> action); "
        "default: actions drawn from the action space with the job's seed",
    )
    p.add_argument("--algo", default="PPO", help="stable-baselines3 algorithm of a .zip (PPO)")
    p.add_argument(
        "--register",
        action="append",
        default=[],
        metavar="MODULE",
        help="import MODULE on each node before gymnasium.make (repeatable), for environments "
        "it registers (autodrive/<Name>-v0 ids need none: autodrive.gym registers them)",
    )
    p.add_argument("--job", default=default_job, help=f"the job function (default {default_job})")
    if kind == "rollouts":
        p.add_argument("--steps", type=int, default=256, help="transitions per job (256)")
    p.add_argument("--workers", type=int, default=2, help="local Ray: jobs at a time (2)")
    p.add_argument("--address", default=None, metavar="HOST:PORT", help="join this Ray cluster")
    p.add_argument("--serial", action="store_true", help="no Ray: one job after the other here")
    p.add_argument(
        "--out", default=str(OUT_DIR / "sweep" / kind), help=f"output folder (out/sweep/{kind})"
    )
    args = p.parse_args(argv)
    if args.seeds < 1:
        p.error(f"--seeds {args.seeds}: need at least 1 seed")
    if args.workers < 1:
        p.error(f"--workers {args.workers}: need at least 1 worker")
    if args.serial and args.address:
        p.error(f"--address {args.address} and --serial: choose one")
    if kind == "rollouts" and args.steps < 1:
        p.error(f"--steps {args.steps}: need at least 1 step")
    if args.policy and args.policy.endswith(".zip") and not Path(args.policy).is_file():
        p.error(f"--policy {args.policy}: no such file")
    import gymnasium

    try:  # fail here, once, not on every node
        resolve(args.job, "--job")
        for module in _modules_for(args.env, args.register):
            importlib.import_module(module)
        if args.policy and not args.policy.endswith(".zip"):
            resolve(args.policy, "--policy")
        gymnasium.spec(args.env)
    except (ValueError, ImportError) as e:
        p.error(str(e))
    except gymnasium.error.Error as e:
        p.error(f"--env {args.env}: {e}")
    return args


def _specs(kind: str, args: argparse.Namespace) -> list[LearnJob]:
    policy, policy_zip = args.policy, None
    if policy and policy.endswith(".zip"):
        policy_zip = Path(policy).read_bytes()
    options = {"steps": args.steps} if kind == "rollouts" else {}
    seeds = range(args.first_seed, args.first_seed + args.seeds)
    return [
        LearnJob(
            args.job, args.env, s, policy, args.algo, tuple(args.register), options, policy_zip
        )
        for s in seeds
    ]


def _plot_eval(png: Path, env_id: str, per: list[dict[str, Any]]) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 4))
    seeds = [r["seed"] for r in per]
    ax.bar(range(len(per)), [r["return"] for r in per], color="tab:blue")
    ax.set_xticks(range(len(per)), [str(s) for s in seeds])
    ax.set_xlabel("seed")
    ax.set_ylabel("episode return")
    ax.set_title(f"{env_id}: {len(per)} evaluation episodes")
    fig.tight_layout()
    fig.savefig(png, dpi=100)
    plt.close(fig)


def _summary_eval(per: list[dict[str, Any]]) -> dict[str, Any]:
    rets = [float(r["return"]) for r in per]
    return {
        "episodes": len(per),
        "return_mean": round(statistics.fmean(rets), 6),
        "return_median": round(statistics.median(rets), 6),
        "return_min": min(rets),
        "return_max": max(rets),
        "length_median": statistics.median(int(r["length"]) for r in per),
        "per_seed": per,
    }


def _summary_rollouts(out: Path, per: list[dict[str, Any]]) -> dict[str, Any]:
    npz = out / "rollouts.npz"
    np.savez_compressed(
        npz,
        seed=np.concatenate([np.full(len(r["rewards"]), r["seed"]) for r in per]),
        obs=np.concatenate([r["obs"] for r in per]),
        actions=np.concatenate([r["actions"] for r in per]),
        rewards=np.concatenate([r["rewards"] for r in per]),
        dones=np.concatenate([r["dones"] for r in per]),
    )
    returns = [x for r in per for x in r["episode_returns"]]
    return {
        "jobs": len(per),
        "transitions": int(sum(len(r["rewards"]) for r in per)),
        "episodes_finished": len(returns),
        "episode_return_median": statistics.median(returns) if returns else None,
        "reward_sum_per_seed": [round(float(np.sum(r["rewards"])), 6) for r in per],
        "rollouts_npz": str(npz),
    }


def main(kind: str, argv: list[str]) -> int:
    args = parse_args(kind, argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    specs = _specs(kind, args)
    try:
        pool = sweep_ray.open_pool(args.workers, args.address, args.serial)
    except (ValueError, RuntimeError) as e:
        log(f"[{kind}] ERROR: {e}")
        return 2
    log(
        f"[{kind}] {len(specs)} job(s) of {args.env} {pool.describe()}; ready in {pool.init_s:.1f} s"
    )
    finished = 0

    def done(i: int, r: dict[str, Any], host: str, wall_s: float) -> None:
        nonlocal finished
        finished += 1
        figure = (
            f"return {r['return']:g}" if "return" in r else f"{len(r.get('rewards', []))} steps"
        )
        log(
            f"[{kind} {finished}/{len(specs)}] seed {specs[i].seed} on {host}: {figure} ({wall_s:.2f} s)"
        )

    try:
        per = sweep_ray.run_jobs(pool, run_learn_job, specs, done)
    finally:
        sweep_ray.close_pool(pool)
    if kind == "eval":
        summary = _summary_eval(per)
        _plot_eval(out / "eval.png", args.env, per)
    else:
        summary = _summary_rollouts(out, per)
    summary.update(env=args.env, policy=args.policy, job=args.job, pool=pool.describe())
    (out / f"{kind}.json").write_text(json.dumps(summary, indent=2) + "\n")
    log(f"[{kind}] wrote {out / (kind + '.json')}")
    print(json.dumps(summary), flush=True)
    return 0
