"""A small random intersection policy exported with PyTorch for the tests: NAME.onnx (input
`obs`, output `action`, the layout of the MARL core) and NAME.json beside it."""

import json
from pathlib import Path

import torch

OBS_DIM = 24  # ADM_OBS_DIM of <autodrive/marl_core.h>, observation version 1
OBS_VERSION = 1
STEERING = [-1.0, 0.0, 1.0]
LOOKAHEAD_M = 0.35


def make_policy(folder: Path, seed: int = 3, throttle: float = 0.6) -> tuple[Path, torch.nn.Module]:
    """The network and NAME.json in the sidecar format of autodrive.learn.marl.export."""
    torch.manual_seed(seed)
    net = torch.nn.Sequential(
        torch.nn.Linear(OBS_DIM, 128),
        torch.nn.Tanh(),
        torch.nn.Linear(128, 128),
        torch.nn.Tanh(),
        torch.nn.Linear(128, 128),
        torch.nn.Tanh(),
        torch.nn.Linear(128, len(STEERING)),
    ).eval()
    onnx_path = folder / "random_policy.onnx"
    torch.onnx.export(
        net,
        torch.zeros(1, OBS_DIM),
        str(onnx_path),
        input_names=["obs"],
        output_names=["action"],
        dynamic_axes={"obs": {0: "n"}, "action": {0: "n"}},
        opset_version=12,
    )
    spec = {
        "obs": {"layout_version": OBS_VERSION, "dim": OBS_DIM, "builder": "autodrive_marl_core"},
        "action": {"type": "discrete", "throttle_steering": [[throttle, s] for s in STEERING]},
        "control_period_s": 0.1,
    }
    onnx_path.with_suffix(".json").write_text(json.dumps(spec))
    return onnx_path, net
