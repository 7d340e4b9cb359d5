"""The PNG figures of behavioural cloning (matplotlib, Agg): loss curves, the steering
histogram before and after balancing, a lap of predictions against the expert (the paper's
Figure 6), activation maps and saliency."""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import numpy.typing as npt  # noqa: E402

DPI = 110
Arr = npt.NDArray[Any]


def _save(fig: Any, path: Path) -> None:
    tmp = path.with_name(path.name + ".tmp")
    fig.savefig(tmp, format="png", dpi=DPI, bbox_inches="tight")
    plt.close(fig)
    os.replace(tmp, path)


def losses(path: Path, history: Mapping[str, Sequence[float]], batches_per_epoch: int) -> None:
    fig, ax = plt.subplots(figsize=(7, 4))
    b = np.asarray(history["batch_loss"], dtype=np.float64)
    if len(b):
        x = np.arange(1, len(b) + 1) / batches_per_epoch
        ax.plot(x, b, color="0.8", lw=0.8, label="training batches (augmented)")
    ep = np.arange(1, len(history["train"]) + 1)
    ax.plot(ep, history["train"], "o-", label="training, epoch mean")
    ax.plot(ep, history["val"], "s-", label="validation laps (not augmented)")
    ax.set_yscale("log")
    ax.set_xlabel("epoch")
    ax.set_ylabel("MSE of normalised steering")
    ax.grid(True, alpha=0.3)
    ax.legend()
    ax.set_title("Behavioural cloning: loss")
    _save(fig, path)


def steering_hist(path: Path, recorded: Arr, drawn: Arr) -> None:
    fig, ax = plt.subplots(figsize=(7, 3.5))
    edges = [float(v) for v in np.linspace(-1, 1, 41)]
    ax.hist(recorded, edges, alpha=0.6, density=True, label="recorded (training laps)")
    if len(drawn):
        ax.hist(drawn, edges, alpha=0.6, density=True, label="drawn: balanced + augmented")
    ax.set_xlabel("steering (normalised, + left)")
    ax.set_ylabel("density")
    ax.legend()
    _save(fig, path)


def lap(path: Path, t_s: Arr, expert: Arr, predicted: Arr, commanded: Arr, title: str) -> None:
    fig, ax = plt.subplots(figsize=(10, 3.8))
    ax.plot(t_s, commanded, color="0.75", lw=0.8, label="commanded (with perturbations)")
    ax.plot(t_s, expert, lw=1.2, label="expert (pure pursuit)")
    ax.plot(t_s, predicted, lw=1.0, label="network, from the camera alone")
    ax.set_xlabel("time in the lap [s]")
    ax.set_ylabel("steering (normalised, + left)")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="lower right", fontsize=8)
    ax.set_title(title)
    _save(fig, path)


def activations(path: Path, frame_rgb: Arr, layers: Sequence[Arr], saliency: Arr) -> None:
    """The input frame, up to 8 channels of each given layer, and the saliency overlay."""
    n = len(layers)
    fig, axes = plt.subplots(n + 1, 8, figsize=(14, 1.6 * (n + 1) + 0.6))
    for ax in axes.ravel():
        ax.axis("off")
    axes[0][0].imshow(frame_rgb)
    axes[0][0].set_title("input", fontsize=8)
    axes[0][1].imshow(saliency, cmap="inferno")
    axes[0][1].set_title("VisualBackProp", fontsize=8)
    axes[0][2].imshow(frame_rgb)
    axes[0][2].imshow(saliency, cmap="inferno", alpha=0.55)
    axes[0][2].set_title("overlay", fontsize=8)
    for li, a in enumerate(layers):
        for c in range(min(8, a.shape[0])):
            axes[li + 1][c].imshow(a[c], cmap="viridis")
            axes[li + 1][c].set_title(f"conv{li + 1} ch{c}", fontsize=7)
    _save(fig, path)
