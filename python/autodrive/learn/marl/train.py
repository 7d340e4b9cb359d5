"""PPO (stable-baselines3) with one policy shared by every car, on the paper's
hyperparameters: 3 x 128 MLP, batch 64, rollout buffer 1024 (n_steps x slots), learning rate
3e-4 decaying linearly, entropy 1e-3, clip 0.2, GAE lambda 0.98, 3 epochs, gamma 0.99. A
curriculum of stages "cars:steps" (one agent first, then four) continues one model.

Checkpoint selection (validate_episodes > 0): from validate_from agent steps on, every
validate_every agent steps and at the end, the policy is exported and run (argmax, with the
shield if it trains with it) on validate_episodes seeded episodes of the last stage's car count
from VALIDATION_SEED, a seed range disjoint from the training seeds (base + copy x 1 000 003 +
episode, below 1e8) and from the held-out evaluation seeds (from 1e9). The best checkpoint is
kept: no collision or off road first, then the most successful episodes, then the later one.
PPO's training rollouts are stochastic and its last update is not its best; the evaluation's
goal is on argmax episodes, so this selects on what the goal measures."""

from __future__ import annotations

import json
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from stable_baselines3 import PPO
from stable_baselines3.common.callbacks import BaseCallback

from autodrive.core.proc import cpu_s
from autodrive.learn.marl.env import STEER_RATE_PENALTY
from autodrive.learn.marl.vec import EnvSpec, MarlVecEnv

BUFFER = 1024
BATCH = 64
LR = 3e-4
VALIDATION_SEED = 500_000_000  # checkpoint selection's episodes start here (see the docstring)


@dataclass
class Curve:
    """Learning curve points: one per finished rollout."""

    timesteps: list[int] = field(default_factory=list)
    wall_s: list[float] = field(default_factory=list)
    cars: list[int] = field(default_factory=list)
    mean_return: list[float] = field(default_factory=list)
    success_rate: list[float] = field(default_factory=list)
    collision_rate: list[float] = field(default_factory=list)


class Progress(BaseCallback):
    """Progress lines and the learning curve from the environments' episode infos."""

    def __init__(
        self,
        curve: Curve,
        cars: int,
        total: int,
        t0: float,
        log: Any,
        max_wall_s: float,
        validator: Validator | None = None,
    ) -> None:
        super().__init__()
        self.max_wall_s = max_wall_s
        self.validator = validator
        self.curve, self.cars, self.total, self.t0, self.log = curve, cars, total, t0, log
        self.returns: list[float] = []
        self.outcomes: list[str] = []
        self.start_steps = 0

    def _on_training_start(self) -> None:
        self.start_steps = self.num_timesteps

    def _on_step(self) -> bool:
        for info in self.locals["infos"]:
            if "episode" in info:
                self.returns.append(float(info["episode"]["r"]))
                self.outcomes.append(str(info.get("outcome", "")))
        return time.monotonic() - self.t0 < self.max_wall_s

    def _on_rollout_end(self) -> None:
        self._log_rollout()
        if self.validator is not None and self.validator.due(int(self.num_timesteps)):
            assert isinstance(self.model, PPO)
            self.validator(self.model)

    def _log_rollout(self) -> None:
        if not self.returns:
            return
        c = self.curve
        c.timesteps.append(int(self.num_timesteps))
        c.wall_s.append(time.monotonic() - self.t0)
        c.cars.append(self.cars)
        c.mean_return.append(float(np.mean(self.returns)))
        c.success_rate.append(float(np.mean([o == "goal" for o in self.outcomes])))
        c.collision_rate.append(float(np.mean([o == "collision" for o in self.outcomes])))
        done = self.num_timesteps - self.start_steps
        self.log(
            f"{self.cars} car(s): {done}/{self.total} steps ({100 * done / self.total:.0f} %), "
            f"{c.wall_s[-1]:.0f} s, agent episodes {len(self.returns)}: mean return "
            f"{c.mean_return[-1]:.2f}, at goal {c.success_rate[-1]:.2f}, collided "
            f"{c.collision_rate[-1]:.2f}"
        )
        self.returns.clear()
        self.outcomes.clear()


@dataclass
class TrainConfig:
    stages: list[tuple[int, int]]  # (cars, agent steps)
    action_mode: str = "discrete"
    copies: int = 2
    workers: int = 2
    seed: int = 0
    torch_threads: int = 1
    max_wall_s: float = float("inf")  # stop (and keep the model) after this wall time
    buffer: int = BUFFER  # rollout buffer (n_steps x slots); smaller only for quick tests
    ray_address: str = ""  # rollouts on Ray actors of this cluster ("": local processes)
    shield: bool = False  # train with the shield in the loop (it brakes; the policy steers)
    shaping: str = "progress"  # the shaping reward (env.SHAPINGS)
    steer_rate_penalty: float = STEER_RATE_PENALTY  # continuous mode: per unit of change per step
    validate_episodes: int = 0  # checkpoint selection's episodes per checkpoint (0: off)
    validate_from: int = 0  # agent steps (whole curriculum) before the first checkpoint
    validate_every: int = 50_000  # agent steps between checkpoints
    validate_workers: int = 2  # processes for the validation episodes


class Validator:
    """Checkpoint selection (see the module docstring): runs the validation episodes on the
    model as it is now and keeps a copy of the best weights."""

    def __init__(self, cfg: TrainConfig, workdir: Path, log: Any) -> None:
        self.cfg, self.workdir, self.log = cfg, workdir, log
        self.cars = cfg.stages[-1][0]
        self.next_at = cfg.validate_from
        self.results: list[dict[str, Any]] = []
        self.best_key: tuple[Any, ...] | None = None
        self.best_state: dict[str, Any] | None = None
        self.last_steps = -1

    def due(self, steps: int) -> bool:
        return self.cfg.validate_episodes > 0 and steps >= self.next_at

    def __call__(self, model: PPO) -> None:
        import copy

        from autodrive.learn.marl.evaluate import evaluate
        from autodrive.learn.marl.export import export

        steps = int(model.num_timesteps)
        if steps == self.last_steps:
            return
        self.last_steps = steps
        while self.next_at <= steps:
            self.next_at += self.cfg.validate_every
        t0 = time.monotonic()
        onnx = self.workdir / "checkpoint.onnx"
        export(model, onnx, self.cfg.action_mode, {})
        mode = "shield" if self.cfg.shield else "no_shield"
        r = evaluate(
            onnx,
            self.cfg.validate_episodes,
            self.cars,
            VALIDATION_SEED,
            mode,
            self.cfg.validate_workers,
        )
        row = {
            "agent_steps": steps,
            "success_rate": r["success_rate"],
            "collisions": r["collisions"],
            "off_road": r["off_road"],
            "timeouts": r["timeouts"],
            "mean_traverse_s": round(r["mean_traverse_s"], 3),
            "wall_s": round(time.monotonic() - t0, 1),
        }
        self.results.append(row)
        key = (r["collisions"] + r["off_road"] == 0, r["success_rate"], steps)
        best = self.best_key is None or key > self.best_key
        if best:
            self.best_key = key
            self.best_state = copy.deepcopy(model.policy.state_dict())
        self.log(
            f"validation at {steps} steps ({self.cfg.validate_episodes} episodes, {mode}): "
            f"success {row['success_rate']:.3f}, collisions {row['collisions']}, off road "
            f"{row['off_road']}, timeouts {row['timeouts']} ({row['wall_s']} s)"
            + (", best so far" if best else "")
        )

    def restore_best(self, model: PPO) -> dict[str, Any] | None:
        """Loads the best checkpoint's weights into model; returns its validation row."""
        if self.best_state is None or self.best_key is None:
            return None
        model.policy.load_state_dict(self.best_state)
        steps = self.best_key[2]
        return next(r for r in self.results if r["agent_steps"] == steps)


def linear(lr0: float) -> Any:
    return lambda progress_remaining: lr0 * progress_remaining


def train(
    cfg: TrainConfig, log: Any, workdir: Path | None = None
) -> tuple[PPO, Curve, dict[str, Any]]:
    """Runs the curriculum; workdir holds checkpoint selection's exported checkpoint."""
    import tempfile

    import torch

    torch.set_num_threads(cfg.torch_threads)
    curve = Curve()
    model: PPO | None = None
    t0 = time.monotonic()
    total_all = sum(s for _, s in cfg.stages)
    done_all = 0
    tmp = tempfile.TemporaryDirectory(prefix="marl-validate-") if workdir is None else None
    where = workdir if tmp is None else Path(tmp.name)
    validator = Validator(cfg, where, log) if cfg.validate_episodes and where else None
    for cars, steps in cfg.stages:
        env = MarlVecEnv(
            EnvSpec(cars, cfg.action_mode, cfg.shield, cfg.shaping, cfg.steer_rate_penalty),
            cfg.copies,
            cfg.workers,
            cfg.seed + 7 * cars,
            cfg.ray_address,
        )
        n_steps = max(1, cfg.buffer // env.num_envs)
        # the learning rate decays linearly over the whole curriculum
        lr0 = LR * (1.0 - done_all / total_all)
        prev = model
        model = PPO(
            "MlpPolicy",
            env,
            learning_rate=linear(lr0),
            n_steps=n_steps,
            batch_size=min(BATCH, n_steps * env.num_envs),
            n_epochs=3,
            gamma=0.99,
            gae_lambda=0.98,
            clip_range=0.2,
            ent_coef=1e-3,
            policy_kwargs={"net_arch": {"pi": [128, 128, 128], "vf": [128, 128, 128]}},
            seed=cfg.seed,
            verbose=0,
            device="cpu",
        )
        if prev is not None:  # the next stage continues the same weights
            model.policy.load_state_dict(prev.policy.state_dict())
            model.num_timesteps = done_all
        log(f"stage: {cars} car(s), {steps} agent steps, {env.num_envs} slots x {n_steps} steps")
        last = (cars, steps) == cfg.stages[-1] and done_all + steps == total_all
        cb = Progress(curve, cars, steps, t0, log, cfg.max_wall_s, validator if last else None)
        model.learn(total_timesteps=steps, callback=cb, reset_num_timesteps=False)
        env.close()
        done_all += steps
        if time.monotonic() - t0 >= cfg.max_wall_s:
            log(f"wall-time budget {cfg.max_wall_s:.0f} s reached at {model.num_timesteps} steps")
            break
    assert model is not None
    chosen = None
    if validator is not None:
        validator(model)  # the final weights (skipped if just validated)
        chosen = validator.restore_best(model)
        log(f"checkpoint selection: kept the weights of {chosen}")
    if tmp is not None:
        tmp.cleanup()
    info = {
        "stages": [{"cars": c, "agent_steps": s} for c, s in cfg.stages],
        "agent_steps_done": int(model.num_timesteps),
        # checkpoint selection: every validation, and the one whose weights were kept
        "validation": {
            "first_seed": VALIDATION_SEED,
            "checkpoints": validator.results if validator else [],
            "kept": chosen,
        },
        "curve_last": {k: v[-1] for k, v in asdict(curve).items() if v},
        "wall_s": round(time.monotonic() - t0, 1),
        # this process and its finished rollout workers (each stage's workers are joined)
        "cpu_s": round(cpu_s(), 1),
        "config": asdict(cfg),
        "hyperparameters": {
            "net": "3 x 128 MLP (tanh), separate policy and value nets",
            "buffer": BUFFER,
            "batch": BATCH,
            "learning_rate": f"{LR} linear decay",
            "ent_coef": 1e-3,
            "clip_range": 0.2,
            "gae_lambda": 0.98,
            "n_epochs": 3,
            "gamma": 0.99,
            "shaping": cfg.shaping,
            "steer_rate_penalty": cfg.steer_rate_penalty,
        },
    }
    return model, curve, info


def plot_curve(curve: Curve, path: Path, title: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    ts = np.asarray(curve.timesteps)
    ax[0].plot(ts, curve.mean_return, label="mean agent return")
    ax[0].set_ylabel("return")
    ax[1].plot(ts, curve.success_rate, label="agent at goal")
    ax[1].plot(ts, curve.collision_rate, label="agent collided")
    ax[1].set_ylabel("fraction of agent episodes")
    ax[1].set_xlabel("agent steps")
    for cars in sorted(set(curve.cars))[1:]:
        first = ts[curve.cars.index(cars)]
        for a in ax:
            a.axvline(first, color="grey", ls="--")
    ax[0].set_title(title)
    for a in ax:
        a.legend(loc="best")
        a.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def save_curve(curve: Curve, path: Path) -> None:
    path.write_text(json.dumps(asdict(curve)) + "\n")


def write_results(
    model: PPO, curve: Curve, info: dict[str, Any], onnx: Path, out: Path, action_mode: str
) -> Path:
    """A training's learning curve (out/learning_curve.json and .png), SB3 model
    (out/ppo_policy.zip), ONNX policy with its sidecar, and report (out/train_report.json);
    returns the sidecar's path."""
    from autodrive.learn.marl.export import export

    out.mkdir(parents=True, exist_ok=True)
    model.save(out / "ppo_policy.zip")
    save_curve(curve, out / "learning_curve.json")
    plot_curve(curve, out / "learning_curve.png", f"PPO, shared policy, {action_mode} actions")
    sidecar = export(model, onnx, action_mode, info)
    (out / "train_report.json").write_text(json.dumps(info, indent=2) + "\n")
    return sidecar
