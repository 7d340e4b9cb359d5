"""Test fixture of the pilot_drive suite: a small random CNN exported with Debian's torch in the
cloning model contract's format (NAME.onnx: input `frames` float32 [N,3,H,W], output `steering`
[N,1]; NAME.json: the preprocessing, opset, onnx_sha256), camera-sized JPEG frames, and the
contract's preprocessing in Python (OpenCV). Never the shipped model: models/pilot/ is
pilot-train's."""

from __future__ import annotations

import hashlib
import json
import pathlib
from typing import Any

import cv2
import numpy as np
import torch
from torch import nn

SOURCE_W, SOURCE_H = 640, 480  # the simulator's front camera
INPUT = {
    "source_width": SOURCE_W,
    "source_height": SOURCE_H,
    "crop_top_px": 200,
    "crop_bottom_px": 40,
    "width": 200,
    "height": 66,
    "colour": "yuv",
    "scale": 1 / 255.0,
    "mean": [0.5, 0.5, 0.5],
    "std": [0.25, 0.25, 0.25],
}


class TinyPilotNet(nn.Module):
    """PilotNet's shape, smaller: conv layers, then dense layers to one steering value."""

    def __init__(self) -> None:
        super().__init__()
        self.features = nn.Sequential(
            nn.Conv2d(3, 8, 5, stride=2), nn.ELU(),
            nn.Conv2d(8, 12, 5, stride=2), nn.ELU(),
            nn.Conv2d(12, 16, 3, stride=2), nn.ELU(),
        )  # fmt: skip
        # 66 x 200 input -> 16 x 6 x 23 features
        self.head = nn.Sequential(
            nn.Flatten(), nn.Linear(16 * 6 * 23, 16), nn.ELU(), nn.Linear(16, 1)
        )

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return torch.tanh(self.head(self.features(x)))


def export(out: pathlib.Path, name: str = "tiny", seed: int = 0, opset: int = 11,
           spec: dict[str, Any] | None = None) -> tuple[pathlib.Path, nn.Module]:  # fmt: skip
    """Writes out/NAME.onnx and NAME.json; returns the .onnx path and the torch model."""
    torch.manual_seed(seed)
    net = TinyPilotNet().eval()
    dummy = torch.zeros(1, 3, INPUT["height"], INPUT["width"])  # type: ignore[call-overload]
    onnx_path = out / f"{name}.onnx"
    torch.onnx.export(net, dummy, str(onnx_path), input_names=["frames"],
                      output_names=["steering"], opset_version=opset,
                      dynamic_axes={"frames": {0: "n"}, "steering": {0: "n"}})  # fmt: skip
    sidecar = {
        "input": spec or INPUT,
        "opset": opset,
        "onnx_sha256": hashlib.sha256(onnx_path.read_bytes()).hexdigest(),
        "trained": {"note": "random weights: the pilot_drive test fixture", "seed": seed},
    }
    onnx_path.with_suffix(".json").write_text(json.dumps(sidecar, indent=2))
    return onnx_path, net


def frames(out: pathlib.Path, n: int = 20, seed: int = 0) -> list[pathlib.Path]:
    """n JPEG frames of the camera's size: a road-like scene (grey floor, two lane lines whose
    position moves from frame to frame) with noise, so the network's outputs differ."""
    rng = np.random.default_rng(seed)
    paths = []
    for i in range(n):
        img = np.full((SOURCE_H, SOURCE_W, 3), 90, np.uint8)
        img[: SOURCE_H // 3] = (200, 170, 140)  # sky / wall
        shift = int(rng.integers(-120, 120))
        for x0 in (180 + shift, 460 + shift):
            cv2.line(
                img, (x0, SOURCE_H), (SOURCE_W // 2 + shift // 3, SOURCE_H // 3), (255, 255, 255), 8
            )
        img = np.clip(img + rng.normal(0, 12, img.shape), 0, 255).astype(np.uint8)
        p = out / f"frame_{i:02d}.jpg"
        cv2.imwrite(str(p), img, [cv2.IMWRITE_JPEG_QUALITY, 90])
        paths.append(p)
    return paths


def preprocess(bgr: np.ndarray, spec: dict[str, Any]) -> np.ndarray:
    """The contract's preprocessing: crop rows, resize INTER_AREA, colour, scale/mean/std, NCHW."""
    h = bgr.shape[0]
    rows = bgr[spec["crop_top_px"] : h - spec["crop_bottom_px"]]
    small = cv2.resize(rows, (spec["width"], spec["height"]), interpolation=cv2.INTER_AREA)
    conv = {"yuv": cv2.COLOR_BGR2YUV, "rgb": cv2.COLOR_BGR2RGB}.get(spec["colour"])
    coloured = cv2.cvtColor(small, conv) if conv is not None else small
    f = coloured.astype(np.float32) * np.float32(spec["scale"])
    f = (f - np.float32(spec["mean"])) / np.float32(spec["std"])
    return np.ascontiguousarray(f.transpose(2, 0, 1)[None])
