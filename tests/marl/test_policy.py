"""marl.policy: a short PPO run through the shared-parameter vectorisation on two worker
processes, its ONNX export read by OpenCV DNN (as the C++ side can) matches PyTorch on 100
observations, the sidecar names the layout, and evaluation runs the exported policy with the
shield and the baseline on the same seed."""

import json
import tempfile
from pathlib import Path

import numpy as np

from autodrive_tools.marl.core import OBS_DIM, OBS_VERSION
from autodrive_tools.marl.evaluate import evaluate
from autodrive_tools.marl.export import OnnxPolicy, export, torch_actions
from autodrive_tools.marl.train import TrainConfig, train


def main() -> None:
    cfg = TrainConfig(stages=[(1, 128), (2, 128)], copies=2, workers=2, seed=3)
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
            r = evaluate(path, 1, 2, 1_000_000_000, mode)
            assert r["episodes"] == 1 and 0.0 <= r["success_rate"] <= 1.0
            if mode == "baseline":
                assert r["success_rate"] == 1.0 and r["collisions"] == 0, r
        print("evaluation ran with the shield and the baseline")
    print("marl.policy: all passed")


if __name__ == "__main__":
    main()
