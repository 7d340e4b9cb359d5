"""PPO (stable-baselines3) with one policy shared by every car, on the paper's
hyperparameters: 3 x 128 MLP, batch 64, rollout buffer 1024 (n_steps x slots), learning rate
3e-4 decaying linearly, entropy 1e-3, clip 0.2, GAE lambda 0.98, 3 epochs, gamma 0.99. A
curriculum of stages "cars:steps" (one agent first, then four) continues one model."""

from __future__ import annotations

import json
import resource
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from stable_baselines3 import PPO
from stable_baselines3.common.callbacks import BaseCallback

from .vec import EnvSpec, MarlVecEnv

BUFFER = 1024
BATCH = 64
LR = 3e-4


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
        self, curve: Curve, cars: int, total: int, t0: float, log: Any, max_wall_s: float
    ) -> None:
        super().__init__()
        self.max_wall_s = max_wall_s
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


def cpu_s() -> float:
    """User + system CPU time [s] of this process and its reaped children."""
    me, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(
        resource.RUSAGE_CHILDREN
    )
    return me.ru_utime + me.ru_stime + kids.ru_utime + kids.ru_stime


def linear(lr0: float) -> Any:
    return lambda progress_remaining: lr0 * progress_remaining


def train(cfg: TrainConfig, log: Any) -> tuple[PPO, Curve, dict[str, Any]]:
    import torch

    torch.set_num_threads(cfg.torch_threads)
    curve = Curve()
    model: PPO | None = None
    t0 = time.monotonic()
    total_all = sum(s for _, s in cfg.stages)
    done_all = 0
    for cars, steps in cfg.stages:
        env = MarlVecEnv(
            EnvSpec(cars, cfg.action_mode, cfg.shield, cfg.shaping),
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
        cb = Progress(curve, cars, steps, t0, log, cfg.max_wall_s)
        model.learn(total_timesteps=steps, callback=cb, reset_num_timesteps=False)
        env.close()
        done_all += steps
        if time.monotonic() - t0 >= cfg.max_wall_s:
            log(f"wall-time budget {cfg.max_wall_s:.0f} s reached at {model.num_timesteps} steps")
            break
    assert model is not None
    info = {
        "stages": [{"cars": c, "agent_steps": s} for c, s in cfg.stages],
        "agent_steps_done": int(model.num_timesteps),
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
    """A training's learning curve (out/learning_curve.json), ONNX policy with its sidecar, and
    report (out/train_report.json); returns the sidecar's path."""
    from .export import export

    out.mkdir(parents=True, exist_ok=True)
    save_curve(curve, out / "learning_curve.json")
    sidecar = export(model, onnx, action_mode, info)
    (out / "train_report.json").write_text(json.dumps(info, indent=2) + "\n")
    return sidecar
