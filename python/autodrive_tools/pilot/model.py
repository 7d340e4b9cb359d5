"""The cloning network: the paper's six-layer CNN, PilotNet-like and small. Four convolutions
(5x5 stride 2 with 24, 36, 48 filters, then 3x3 with 64) and two fully connected layers (100,
then the steering), ELU between them, dropout before the first dense layer. On a 66x200 input
it has ~0.5 M parameters (~2 MB as float32 ONNX). A tanh keeps the output in [-1, 1] (not a
clamp: OpenCV 4.6's ONNX reader refuses opset 11's Clip with bounds as inputs)."""

from __future__ import annotations

from typing import Any

import torch
from torch import nn

CONV_LAYERS = 4  # the first three are the ones `tools/pilot analyse` shows


class PilotNet(nn.Module):
    def __init__(self, height: int, width: int, dropout: float = 0.3) -> None:
        super().__init__()
        self.act = nn.ELU()
        self.convs = nn.ModuleList(
            [
                nn.Conv2d(3, 24, 5, stride=2),
                nn.Conv2d(24, 36, 5, stride=2),
                nn.Conv2d(36, 48, 5, stride=2),
                nn.Conv2d(48, 64, 3),
            ]
        )
        with torch.no_grad():
            n = self.features(torch.zeros(1, 3, height, width)).shape[1]
        self.dropout = nn.Dropout(dropout)
        self.fc1 = nn.Linear(n, 100)
        self.fc2 = nn.Linear(100, 1)

    def feature_maps(self, x: torch.Tensor) -> list[torch.Tensor]:
        """Each convolution's activations (after ELU), first to last."""
        out = []
        for c in self.convs:
            x = self.act(c(x))
            out.append(x)
        return out

    def features(self, x: torch.Tensor) -> torch.Tensor:
        return torch.flatten(self.feature_maps(x)[-1], 1)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        h = self.act(self.fc1(self.dropout(self.features(x))))
        y: torch.Tensor = torch.tanh(self.fc2(h))
        return y


def parameter_count(net: nn.Module) -> int:
    return sum(int(p.numel()) for p in net.parameters())


def export_onnx(net: PilotNet, path: str, height: int, width: int, opset: int) -> None:
    net.eval()
    dummy = torch.zeros(1, 3, height, width)
    kw: dict[str, Any] = {
        "input_names": ["frames"],
        "output_names": ["steering"],
        "dynamic_axes": {"frames": {0: "N"}, "steering": {0: "N"}},
        "opset_version": opset,
        "do_constant_folding": True,
    }
    torch.onnx.export(net, dummy, path, **kw)
