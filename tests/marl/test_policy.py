"""marl.policy: a short PPO run through the shared-parameter vectorisation on two worker
processes, its ONNX export read by OpenCV DNN (as the C++ side can) matches PyTorch on 100
observations, the sidecar names the layout, and evaluation runs the exported policy with the
shield and the baseline on the same seed; checkpoint selection validates at its steps on its own
seeds and hands back the weights of the best checkpoint."""

import json
import math
import tempfile
from pathlib import Path

import numpy as np

from autodrive.learn.marl.core import OBS_DIM, OBS_VERSION
from autodrive.learn.marl.evaluate import evaluate
from autodrive.learn.marl.export import OnnxPolicy, export, torch_actions
from autodrive.learn.marl.cli import HELD_OUT_SEED
from autodrive.learn.marl.train import VALIDATION_SEED, TrainConfig, train


def test_train_export_evaluate() -> None:
    cfg = TrainConfig(stages=[(1, 128), (2, 128)], copies=2, workers=2, seed=3, buffer=128)
    model, curve, info = train(cfg, print)
    assert info["agent_steps_done"] >= 256
    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "p.onnx"
        export(model, path, "discrete", info)
        meta = json.loads(path.with_suffix(".json").read_text())
        assert meta["obs"] == {
            "layout_version": OBS_VERSION,
            "dim": OBS_DIM,
            "builder": "autodrive_marl_core",
        }
        assert len(meta["action"]["throttle_steering"]) == 3
        obs = np.random.default_rng(0).normal(size=(100, OBS_DIM)).astype(np.float32)
        ref = torch_actions(model, obs)
        got = OnnxPolicy(path).raw(obs)
        err = float(np.abs(ref - got).max())
        assert ref.shape == got.shape == (100, 3), (ref.shape, got.shape)
        assert err < 1e-4, f"ONNX differs from PyTorch by {err}"
        print(f"ONNX (OpenCV DNN) matches PyTorch on 100 observations (max |diff| {err:.2e})")
        for mode in ("shield", "baseline"):
            r = evaluate(path, 1, 2, HELD_OUT_SEED, mode)
            print(mode, {k: r[k] for k in ("success_rate", "collisions", "off_road", "timeouts")})
            # every car of the episode is counted once: at its goal, or as a failure
            cars_failed = r["collisions"] + r["off_road"] + r["timeouts"]
            assert r["episodes"] == 1 and r["success_rate"] in (0.0, 1.0), r
            assert (cars_failed == 0) == (r["success_rate"] == 1.0), r
            assert (r["success_rate"] < 1.0) == bool(r["failed_seeds"]), r
            # the shield stands between the barely trained policy and every collision
            assert r["collisions"] == 0, r
            if mode == "baseline":
                assert r["success_rate"] == 1.0, r
        print("evaluation ran with the shield and the baseline")


def test_checkpoint_selection() -> None:
    cfg = TrainConfig(
        stages=[(1, 384)],
        copies=1,
        workers=1,
        seed=5,
        buffer=128,
        shield=True,
        validate_episodes=2,
        validate_from=128,
        validate_every=128,
        validate_workers=1,
    )
    model, _, info = train(cfg, print)
    v = info["validation"]
    # the validation seeds are neither training seeds (far below) nor held-out ones
    assert v["first_seed"] == VALIDATION_SEED and VALIDATION_SEED + 2 <= HELD_OUT_SEED, v
    rows = v["checkpoints"]
    assert [r["agent_steps"] for r in rows] == [128, 256, 384], rows

    def key(r: dict) -> tuple:
        return (r["collisions"] + r["off_road"] == 0, r["success_rate"], r["agent_steps"])

    assert v["kept"] == max(rows, key=key), v
    # the model handed back is the kept checkpoint: the same validation episodes again
    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "kept.onnx"
        export(model, path, "discrete", info)
        r = evaluate(path, 2, 1, VALIDATION_SEED, "shield")
    again = {k: r[k] for k in ("success_rate", "collisions", "off_road", "timeouts")}
    assert again == {k: v["kept"][k] for k in again}, (again, v["kept"])
    t, kept_t = round(r["mean_traverse_s"], 3), v["kept"]["mean_traverse_s"]
    assert t == kept_t or (math.isnan(t) and math.isnan(kept_t)), (t, kept_t)
    print(f"checkpoint selection kept {v['kept']['agent_steps']} of {len(rows)} checkpoints")
