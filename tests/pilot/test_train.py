"""A tiny dataset (a generated two-lap log: drawn lane frames, ground truth) trains one epoch
and exports: NAME.onnx (input `frames` [N,3,H,W], output `steering` [N,1] in [-1, 1]) and the
sidecar of the contract (its sha256 the file's), which OpenCV's DNN runs with the sidecar's
preprocessing to PyTorch's outputs within 1e-4. Validation is a whole lap not trained on.
The exported graph normalises each frame itself and reads the luma only: a frame at a quarter
of the light gives nearly the same steering, and the chroma channels change nothing.
`tools/pilot analyse` then writes the lap plot and activation maps."""

from __future__ import annotations

import json
import sys
import tempfile
from pathlib import Path

import cv2
import numpy as np
import torch

sys.path.insert(0, str(Path(__file__).parent))
import gen_log  # noqa: E402

from autodrive.learn.pilot import augment, model  # noqa: E402
from autodrive.learn.pilot.analyse import analyse  # noqa: E402
from autodrive.learn.pilot.dataset import record  # noqa: E402
from autodrive.learn.pilot.spec import InputSpec, preprocess, read_sidecar  # noqa: E402
from autodrive.learn.pilot.spec import sha256_file  # noqa: E402
from autodrive.learn.pilot.train import TrainConfig, train  # noqa: E402


def test_balance_weights() -> None:
    """A rare steering is drawn at most max_ratio times as often as a common one; 1: uniform."""
    steer = np.array([0.0] * 90 + [0.4] * 10)
    for ratio, want in ((20.0, 9.0), (3.0, 3.0), (1.0, 1.0)):
        w = augment.balance_weights(steer, ratio)
        assert abs(w.sum() - 1.0) < 1e-9 and abs(w[-1] / w[0] - want) < 1e-9, (ratio, w[-1] / w[0])
    try:
        augment.balance_weights(steer, 0.5)
    except ValueError as e:
        assert "0.5" in str(e)
    else:
        raise AssertionError("a ratio below 1 was taken")


def check_in_graph_preprocessing(net: cv2.dnn.Net, x: np.ndarray, spec: InputSpec) -> None:
    """The exported network (OpenCV's DNN) on night-like frames (every level x 0.25, in the
    sidecar's normalised units) and on frames with other chroma."""
    mean = np.asarray(spec.mean, np.float32)[None, :, None, None]
    std = np.asarray(spec.std, np.float32)[None, :, None, None]
    dark = ((x * std + mean) * 0.25 - mean) / std
    other_chroma = x.copy()
    other_chroma[:, 1:] = np.random.default_rng(0).normal(size=other_chroma[:, 1:].shape)
    outs = []
    for inp in (x, dark.astype(np.float32), other_chroma):
        net.setInput(inp)
        outs.append(net.forward())
    assert np.max(np.abs(outs[1] - outs[0])) < 0.01, np.max(np.abs(outs[1] - outs[0]))
    assert np.max(np.abs(outs[2] - outs[0])) < 1e-6, np.max(np.abs(outs[2] - outs[0]))


def test_train_one_epoch_and_export(build_dir: Path) -> None:
    build = build_dir
    with tempfile.TemporaryDirectory(prefix="pilot-train-") as tmp:
        d = Path(tmp)
        n = gen_log.write(d / "tiny.lcmlog", build, laps=2, frames_per_lap=60)
        m = record([d / "tiny.lcmlog"], d / "ds", map_name="driving_school", seed=0, build=build)
        assert m["frame_count"] == n and m["laps"] == 2, m
        assert m["frames_per_lap"] == {"0": 60, "1": 60}, m["frames_per_lap"]
        cfg = TrainConfig(epochs=1, batch=16, samples_per_epoch=64, seed=0, name="tiny")
        report = train(d / "ds", d / "model", cfg)
        assert len(report["train_loss"]) == 1 and len(report["val_loss"]) == 1
        assert set(report["train_laps"]).isdisjoint(report["val_laps"]), report
        assert report["val_frames"] == 60, report["val_frames"]
        onnx = d / "model" / "tiny.onnx"
        side = read_sidecar(d / "model" / "tiny.json")
        raw = json.loads((d / "model" / "tiny.json").read_text())
        for key in ("source_width", "source_height", "crop_top_px", "crop_bottom_px", "width",
                    "height", "colour", "scale", "mean", "std"):  # fmt: skip
            assert key in raw["input"], key
        assert 11 <= raw["opset"] <= 13 and raw["onnx_sha256"] == sha256_file(onnx)
        assert onnx.stat().st_size < 5e6
        spec = side.input
        frames = sorted((d / "ds" / "frames").glob("*.jpg"))[:20]
        x = np.stack([preprocess(cv2.imread(str(f)), spec) for f in frames])
        assert x.shape == (20, 3, spec.height, spec.width) and x.dtype == np.float32
        net = cv2.dnn.readNetFromONNX(str(onnx))
        net.setInput(x)
        got = net.forward()
        assert got.shape == (20, 1) and np.all(np.abs(got) <= 1.0)
        assert side.trained["channels"] == cfg.channels == 1
        torch_net = model.PilotNet(spec.height, spec.width, channels=side.trained["channels"])
        torch_net.load_state_dict(torch.load(d / "model" / "tiny.pt"))
        torch_net.eval()
        with torch.no_grad():
            want = torch_net(torch.from_numpy(x)).numpy()
        diff = float(np.max(np.abs(got - want)))
        assert diff < 1e-4, diff
        check_in_graph_preprocessing(net, x, spec)
        for f in (
            "loss.png",
            "steering_hist.png",
            f"{cfg.name}_report.json",
            f"{cfg.name}_report.md",
        ):
            assert (d / "model" / f).stat().st_size > 0, f
        res = analyse(onnx, d / "ds", d / "analysis", samples=1)
        assert res["frames"] == 60 and res["lap"] in report["val_laps"]
        for f in res["figures"]:
            assert (d / "analysis" / f).stat().st_size > 1000, f
        print(f"one epoch: val loss {report['val_loss'][0]:.4f}, DNN vs torch {diff:.1e}, ok")
