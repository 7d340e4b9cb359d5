"""ONNX export of a trained policy and its JSON sidecar (the contract: input "obs" float32
[N, D], output "action": logits (discrete) or the mean steering (continuous); the sidecar holds
the observation layout version, D, the action set, the control period and the throttle)."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt
import torch
from stable_baselines3 import PPO

from autodrive.learn.marl.core import OBS_DIM, OBS_VERSION
from autodrive.learn.marl.env import CONTROL_HZ

OPSET = 13


class ActorHead(torch.nn.Module):
    """obs -> the action distribution's parameters (logits or mean), deterministic."""

    def __init__(self, model: PPO) -> None:
        super().__init__()
        self.policy = model.policy

    def forward(self, obs: torch.Tensor) -> torch.Tensor:
        # Box observations: the features extractor only flattens [N, D]; leaving it out keeps
        # Identity nodes (which OpenCV 4.6's importer refuses) out of the graph
        p = self.policy
        out: torch.Tensor = p.action_net(p.mlp_extractor.policy_net(obs))
        return out


def torch_actions(model: PPO, obs: npt.NDArray[np.float32]) -> npt.NDArray[np.float32]:
    """The head's output in PyTorch (what the ONNX file must reproduce)."""
    with torch.no_grad():
        out = ActorHead(model).eval()(torch.as_tensor(obs, dtype=torch.float32))
    return np.asarray(out.numpy(), dtype=np.float32)


def _inline_identities(onnx_path: Path) -> None:
    """torch's exporter shares equal initializers (e.g. zero biases) through Identity nodes,
    which OpenCV 4.6's importer refuses: give each its own copy of the tensor instead."""
    import onnx

    m = onnx.load(str(onnx_path))
    inits = {t.name: t for t in m.graph.initializer}
    keep = []
    for node in m.graph.node:
        if node.op_type == "Identity" and node.input[0] in inits:
            copy = onnx.TensorProto()
            copy.CopyFrom(inits[node.input[0]])
            copy.name = node.output[0]
            m.graph.initializer.append(copy)
        else:
            keep.append(node)
    del m.graph.node[:]
    m.graph.node.extend(keep)
    onnx.checker.check_model(m)
    onnx.save(m, str(onnx_path))


def action_set(action_mode: str) -> dict[str, Any]:
    if action_mode == "continuous":
        return {"type": "continuous", "output": "mean steering in [-1, 1]", "throttle": 1.0}
    table = [[1.0, -1.0], [1.0, 0.0], [1.0, 1.0]]
    if action_mode == "discrete_throttle":
        table += [[0.5, -1.0], [0.5, 0.0], [0.5, 1.0]]
    return {
        "type": "discrete",
        "output": "logits; action = argmax",
        "throttle_steering": table,
        "throttle": 1.0,
    }


def export(model: PPO, onnx_path: Path, action_mode: str, trained: dict[str, Any]) -> Path:
    """Writes onnx_path and its .json sidecar; returns the sidecar's path."""
    onnx_path.parent.mkdir(parents=True, exist_ok=True)
    head = ActorHead(model).eval()
    dummy = torch.zeros((1, OBS_DIM), dtype=torch.float32)
    torch.onnx.export(
        head,
        dummy,
        str(onnx_path),
        input_names=["obs"],
        output_names=["action"],
        dynamic_axes={"obs": {0: "N"}, "action": {0: "N"}},
        opset_version=OPSET,
    )
    _inline_identities(onnx_path)
    side = {
        "obs": {"layout_version": OBS_VERSION, "dim": OBS_DIM, "builder": "autodrive_marl_core"},
        "action": action_set(action_mode),
        "action_mode": action_mode,
        "control_period_s": 1.0 / CONTROL_HZ,
        "opset": OPSET,
        "onnx_sha256": hashlib.sha256(onnx_path.read_bytes()).hexdigest(),
        "trained": trained,
    }
    sidecar = onnx_path.with_suffix(".json")
    sidecar.write_text(json.dumps(side, indent=2) + "\n")
    return sidecar


class OnnxPolicy:
    """A shipped policy run with OpenCV DNN (as the C++ side can): obs [N, D] -> action."""

    def __init__(self, onnx_path: Path) -> None:
        import cv2

        cv2.setNumThreads(1)  # a 24 -> 3 x 128 MLP: threads cost more than they give
        self.meta: dict[str, Any] = json.loads(onnx_path.with_suffix(".json").read_text())
        if self.meta["obs"]["layout_version"] != OBS_VERSION or self.meta["obs"]["dim"] != OBS_DIM:
            raise ValueError(
                f"{onnx_path}: observation layout v{self.meta['obs']['layout_version']} "
                f"D={self.meta['obs']['dim']}, this build has v{OBS_VERSION} D={OBS_DIM}"
            )
        self.net = cv2.dnn.readNetFromONNX(str(onnx_path))
        self.action_mode: str = self.meta["action_mode"]

    def raw(self, obs: npt.NDArray[np.float32]) -> npt.NDArray[np.float32]:
        self.net.setInput(np.ascontiguousarray(obs, dtype=np.float32), "obs")
        return np.asarray(self.net.forward(), dtype=np.float32)

    def act(self, obs: npt.NDArray[np.float32]) -> npt.NDArray[Any]:
        out = self.raw(obs)
        act: npt.NDArray[Any] = (
            np.clip(out, -1.0, 1.0) if self.action_mode == "continuous" else np.argmax(out, axis=1)
        )
        return act
