"""The cloning network: the paper's six-layer CNN, PilotNet-like and small. Four convolutions
(5x5 stride 2 with 24, 36, 48 filters, then 3x3 with 64) and two fully connected layers (100,
then the steering), ELU between them, dropout before the first dense layer. On a 66x200 input
it has ~0.5 M parameters (~2 MB as float32 ONNX).

Two fixed steps come first, in the exported graph, so training, `tools/pilot analyse` and the
C++ `autodrive-pilot` share one definition of them (the input stays the sidecar's [N, 3, H, W]):
- `channels` (1 or 3): the leading input channels used. 1 = the luma of the sidecar's YUV:
  without colour the yellow centre line and the white edge line differ only in brightness and
  dashes. The aim: the network should not take "the yellow line is on the inside of the curve"
  (true on every curve of the recorded loop_ccw, false on every curve of loop_cw) for the
  curve's direction. It did not make loop_cw drivable: the inner lane's tighter curves still
  read as "heading into the centre line" (docs/guides/training.md).
- per-image normalisation (ONNX InstanceNormalization: each channel of each frame to mean 0,
  standard deviation 1, no learned parameters): a darker scene (night) gives the convolutions
  the same input as the day. A tanh keeps the output in [-1, 1] (not a
clamp: OpenCV 4.6's ONNX reader refuses opset 11's Clip with bounds as inputs)."""

from __future__ import annotations

from typing import Any

import torch
from torch import nn

CONV_LAYERS = 4  # the first three are the ones `tools/pilot analyse` shows
# Added to each channel's variance in the per-image normalisation. The input is already the
# sidecar's (x - mean) / std (~unit variance over the training frames): 1e-3 keeps a nearly
# uniform frame (the lens covered) from blowing its noise up without bound.
NORM_EPS = 1e-3


class PilotNet(nn.Module):
    def __init__(self, height: int, width: int, dropout: float = 0.3, channels: int = 1) -> None:
        super().__init__()
        if channels not in (1, 3):
            raise ValueError(f"channels {channels}: 1 (luma) or 3")
        self.channels = channels
        self.act = nn.ELU()
        self.norm = nn.InstanceNorm2d(channels, eps=NORM_EPS, affine=False)
        self.convs = nn.ModuleList(
            [
                nn.Conv2d(channels, 24, 5, stride=2),
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
        x = self.norm(x[:, : self.channels])
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
