"""The C++ policy (autodrive-marl --eval-obs: OpenCV DNN) gives PyTorch's outputs on 100
observations of a random exported policy, and autodrive-marl refuses bad policy files, naming
the file and what is wrong."""

import json
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Callable

import numpy as np
import torch

sys.path.insert(0, str(Path(__file__).parent))
from marl_test_policy import OBS_DIM, make_policy  # noqa: E402


def test_cpp_policy_matches_pytorch(program: Callable[[str], str]) -> None:
    exe = program("autodrive-marl")
    with tempfile.TemporaryDirectory(prefix="marl-policy-") as tmp:
        folder = Path(tmp)
        onnx_path, net = make_policy(folder)
        rng = np.random.default_rng(11)
        obs = rng.uniform(-1.5, 1.5, (100, OBS_DIM)).astype(np.float32)
        csv = folder / "obs.csv"
        csv.write_text("\n".join(",".join(f"{v:.9g}" for v in row) for row in obs) + "\n")
        r = subprocess.run(
            [exe, "--policy", str(onnx_path), "--eval-obs", str(csv)],
            capture_output=True,
            text=True,
            timeout=60,
        )
        assert r.returncode == 0, r.stderr
        cpp = np.array([[float(v) for v in line.split(",")] for line in r.stdout.split()])
        with torch.no_grad():
            ref = net(torch.from_numpy(obs)).numpy()
        assert cpp.shape == ref.shape, (cpp.shape, ref.shape)
        err = float(np.abs(cpp - ref).max())
        same_action = int((cpp.argmax(1) == ref.argmax(1)).sum())
        print(f"100 observations: max |C++ - PyTorch| = {err:.2e}, same action {same_action}/100")
        assert err < 1e-4, err
        assert same_action == 100

        # Bad policy files: refused (exit 2), naming the file and the problem.
        good = json.loads(onnx_path.with_suffix(".json").read_text())
        garbage = folder / "garbage.onnx"
        garbage.write_bytes(b"not a network")
        garbage.with_suffix(".json").write_text(json.dumps(good))
        no_period = {k: v for k, v in good.items() if k != "control_period_s"}
        two = {"type": "discrete", "throttle_steering": [[1, -1], [1, 1]]}
        cases = [
            (onnx_path, no_period, "random_policy.json: control_period_s: missing key"),
            (onnx_path, {**good, "obs": {"layout_version": 1, "dim": 7}}, "obs_dim 7"),
            (
                onnx_path,
                {**good, "action": {"type": "discrete", "throttle_steering": [[1, -1], [1, 2]]}},
                "action.throttle_steering: every entry",
            ),
            (onnx_path, {**good, "action": two}, "its output has 3 values"),
            (onnx_path, {**good, "action": {"type": "beta"}}, "action.type: neither"),
            (garbage, None, "garbage.onnx: OpenCV DNN cannot load it"),
            (folder / "missing.onnx", None, "missing.onnx: no such file"),
        ]
        for path, spec, want in cases:
            if spec is not None:
                path.with_suffix(".json").write_text(json.dumps(spec))
            r = subprocess.run(
                [exe, "--policy", str(path), "--map-json", str(csv), "--route", "x"],
                capture_output=True,
                text=True,
                timeout=60,
            )
            assert r.returncode == 2 and want in r.stderr, (path, want, r.returncode, r.stderr)
            print(f"refused {path.name}: {r.stderr.strip()[:160]}")
    print("ok")
