"""tools/sweep eval / rollouts (autodrive.learn.sweep.episodes) on Gymnasium's CartPole-v1 (the
simulator's own learning environments plug in the same way, --register MODULE): the evaluation
episodes of a random policy on an embedded local Ray with 2 workers equal those run serially,
seed by seed; so do those of a stable-baselines3 PPO .zip (on Debian's torch); a scripted policy
(module:function) balances the pole; rollouts through Ray equal serial ones array by array; bad input
exits 2 naming the option."""

from __future__ import annotations

import json
import os
import pathlib
import subprocess
import tempfile
from typing import Any

import numpy as np


def test_ray_and_serial_agree(root: pathlib.Path) -> None:
    PY = str(root / ".venv" / "bin" / "python")
    ENV = dict(os.environ, RAY_USAGE_STATS_ENABLED="0")

    def sweep(*argv: str, code: int = 0) -> tuple[dict[str, Any], str]:
        r = subprocess.run(
            [PY, "-m", "autodrive.learn.sweep.cli", *argv],
            capture_output=True,
            text=True,
            timeout=240,
            env=ENV,
        )
        assert r.returncode == code, f"{argv}: exit {r.returncode}: {r.stderr}"
        return (json.loads(r.stdout.strip().splitlines()[-1]) if code == 0 else {}), r.stderr

    with tempfile.TemporaryDirectory(prefix="sweep-learn-") as t:
        tmp = pathlib.Path(t)
        common = ["--env", "CartPole-v1", "--seeds", "6"]
        serial, _ = sweep("eval", *common, "--serial", "--out", str(tmp / "s"))
        on_ray, err = sweep("eval", *common, "--workers", "2", "--out", str(tmp / "r"))
        assert "embedded local Ray, 2 worker(s)" in on_ray["pool"], on_ray["pool"]
        assert "[eval 6/6]" in err, err
        assert on_ray["per_seed"] == serial["per_seed"], (on_ray["per_seed"], serial["per_seed"])
        assert len({r["return"] for r in serial["per_seed"]}) > 1, "seeds did not matter"
        assert (tmp / "r" / "eval.png").stat().st_size > 5000, "eval.png missing"
        assert json.loads((tmp / "r" / "eval.json").read_text()) == on_ray

        # A scripted policy balances the pole where random actions drop it within ~20-30 steps.
        scripted, _ = sweep(
            "eval",
            *common,
            "--policy",
            "autodrive.learn.sweep.episodes:cartpole_balance",
            "--serial",
            "--out",
            str(tmp / "b"),
        )
        assert scripted["return_min"] > 5 * serial["return_max"], (scripted, serial["return_max"])

        # A stable-baselines3 policy (an untrained PPO: deterministic actions), torch from Debian.
        import torch
        from stable_baselines3 import PPO

        assert torch.__file__.startswith("/usr/lib/python3/dist-packages/"), torch.__file__
        PPO("MlpPolicy", "CartPole-v1", seed=0, device="cpu").save(tmp / "ppo.zip")
        ppo_ray, _ = sweep(
            "eval", *common, "--policy", str(tmp / "ppo.zip"), "--out", str(tmp / "p")
        )
        ppo_serial, _ = sweep(
            "eval", *common, "--policy", str(tmp / "ppo.zip"), "--serial", "--out", str(tmp / "q")
        )
        assert ppo_ray["per_seed"] == ppo_serial["per_seed"]

        roll = ["rollouts", "--env", "CartPole-v1", "--seeds", "3", "--steps", "120"]
        r_ray, _ = sweep(*roll, "--out", str(tmp / "rr"))
        r_serial, _ = sweep(*roll, "--serial", "--out", str(tmp / "rs"))
        assert r_ray["transitions"] == 360 and r_ray["episodes_finished"] >= 3, r_ray
        a, b = np.load(tmp / "rr" / "rollouts.npz"), np.load(tmp / "rs" / "rollouts.npz")
        for k in ("seed", "obs", "actions", "rewards", "dones"):
            assert np.array_equal(a[k], b[k]), f"rollouts differ in {k}"

        _, err = sweep("eval", "--env", "NoSuchEnv-v0", "--serial", code=2)
        assert "--env NoSuchEnv-v0" in err, err
        _, err = sweep("eval", *common, "--policy", str(tmp / "missing.zip"), code=2)
        assert "missing.zip: no such file" in err, err
        _, err = sweep("eval", *common, "--workers", "0", code=2)
        assert "--workers 0" in err, err
        _, err = sweep("eval", *common, "--address", "127.0.0.1:1", code=2)
        assert "--address 127.0.0.1:1" in err and "no Ray head answers" in err, err
    print("eval and rollouts: Ray and serial agree seed by seed")
