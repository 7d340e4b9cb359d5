"""A small random intersection policy exported with PyTorch for the tests: NAME.onnx (input
`obs`, output `action`, the layout of the MARL core) and NAME.json beside it."""

import json
from pathlib import Path

import torch

OBS_DIM = 24  # ADM_OBS_DIM of <autodrive/marl_core.h>, observation version 1
OBS_VERSION = 1
ACTIONS = [-1.0, 0.0, 1.0]


def make_policy(folder: Path, seed: int = 3, throttle: float = 0.6) -> tuple[Path, torch.nn.Module]:
    torch.manual_seed(seed)
    net = torch.nn.Sequential(
        torch.nn.Linear(OBS_DIM, 128),
        torch.nn.Tanh(),
        torch.nn.Linear(128, 128),
        torch.nn.Tanh(),
        torch.nn.Linear(128, 128),
        torch.nn.Tanh(),
        torch.nn.Linear(128, len(ACTIONS)),
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
        "obs_version": OBS_VERSION,
        "obs_dim": OBS_DIM,
        "actions": ACTIONS,
        "control_period_s": 0.05,
        "throttle": throttle,
        "waypoint_lookahead_m": 0.3,
    }
    onnx_path.with_suffix(".json").write_text(json.dumps(spec))
    return onnx_path, net
