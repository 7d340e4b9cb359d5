"""`tools/pilot analyse`: what the network looks at, from the exported ONNX file run by
OpenCV's DNN module (the engine of the C++ pilot), with the sidecar's preprocessing:
- for sample frames, the activation maps of the first three convolution layers and a
  VisualBackProp-style saliency map (Bojarski et al.): each convolution layer's activations
  averaged over its channels, the deepest one scaled up to the size of the one before and
  multiplied with it, on to the input (bilinear scaling stands in for the paper's
  deconvolution);
- a whole lap of predictions against the expert (like the paper's Figure 6), with the RMSE.
Writes activations_<frame>.png, lap_<k>.png and analysis.json into --out."""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import numpy.typing as npt

from autodrive.learn.pilot import dataset, plots
from autodrive.learn.pilot.spec import F32, crop_resize, decode_jpeg, normalise, read_sidecar

Arr = npt.NDArray[Any]


def log(msg: str) -> None:
    print(f"pilot analyse: {msg}", file=sys.stderr, flush=True)


def conv_activation_layers(net: Any) -> list[str]:
    """The activation layers after each convolution, in order (names from the ONNX export)."""
    names = [str(n) for n in net.getLayerNames()]
    convs = [i for i, n in enumerate(names) if n.endswith("Conv")]
    out = []
    for i in convs:
        nxt = names[i + 1] if i + 1 < len(names) else ""
        out.append(nxt if nxt.endswith("Elu") or nxt.endswith("Relu") else names[i])
    return out


def visual_backprop(maps: list[Arr], size_wh: tuple[int, int]) -> F32:
    """Saliency in [0, 1] at size_wh from activation maps [C, h, w], first to last layer."""
    means = [m.mean(axis=0).astype(np.float32) for m in maps]
    mask = means[-1]
    for prev in reversed(means[:-1]):
        mask = cv2.resize(mask, (prev.shape[1], prev.shape[0]), interpolation=cv2.INTER_LINEAR)
        mask = mask * prev
    mask = cv2.resize(mask, size_wh, interpolation=cv2.INTER_LINEAR)
    mask -= mask.min()
    peak = float(mask.max())
    out: F32 = mask / peak if peak > 0 else mask
    return out


def analyse(
    model_path: Path, data_root: Path, out: Path, lap: int | None = None, samples: int = 3
) -> dict[str, Any]:
    sidecar = read_sidecar(model_path.with_suffix(".json"))
    spec = sidecar.input
    try:
        net = cv2.dnn.readNetFromONNX(str(model_path))
    except cv2.error as e:
        raise ValueError(f"{model_path}: OpenCV's DNN cannot read it ({e})") from e
    ds = dataset.load(data_root)
    laps = sorted({int(r["lap"]) for r in ds.rows})
    if lap is None:
        val = sidecar.trained.get("val_laps") or []
        same = (
            sidecar.trained.get("dataset")
            and Path(sidecar.trained["dataset"]).resolve() == data_root.resolve()
        )
        lap = int(val[0]) if same and val else laps[-1]
    if lap not in laps:
        raise ValueError(f"{data_root}: no lap {lap} (laps {laps})")
    rows = [r for r in ds.rows if int(r["lap"]) == lap and float(r["throttle"] or 0) > 0]
    out.mkdir(parents=True, exist_ok=True)
    layers = conv_activation_layers(net)
    log(f"lap {lap}: {len(rows)} frames; activation layers {layers[:3]}")
    pred = np.empty(len(rows), np.float32)
    for k in range(0, len(rows), 64):
        chunk = rows[k : k + 64]
        x = np.stack(
            [
                normalise(
                    crop_resize(decode_jpeg((data_root / r["file"]).read_bytes(), r["file"]), spec),
                    spec,
                )
                for r in chunk
            ]
        )
        net.setInput(x)
        pred[k : k + len(chunk)] = net.forward().reshape(-1)
    t = np.array([float(r["t_s"]) for r in rows])
    t = t - t[0] if len(t) else t
    expert = np.array([float(r["steering"]) for r in rows])
    cmd = np.array([float(r["command_steering"]) for r in rows])
    rmse = float(np.sqrt(np.mean((pred - expert) ** 2))) if len(rows) else math.nan
    plots.lap(
        out / f"lap_{lap}.png", t, expert, pred, cmd,
        f"lap {lap}: network vs expert, RMSE {rmse:.3f} (normalised steering)",
    )  # fmt: skip
    picks: list[int] = []
    if len(rows):  # evenly spread frames, and the one where the expert steers hardest
        spread = np.linspace(0, len(rows) - 1, samples + 2).astype(int)[1:-1]
        picks = sorted({int(p) for p in spread} | {int(np.argmax(np.abs(expert)))})
    written = []
    for p in picks:
        r = rows[p]
        small = crop_resize(decode_jpeg((data_root / r["file"]).read_bytes(), r["file"]), spec)
        net.setInput(normalise(small, spec)[None])
        maps = [np.asarray(a)[0] for a in net.forward(layers)]
        sal = visual_backprop(maps, (spec.width, spec.height))
        name = f"activations_{int(r['frame']):06d}.png"
        plots.activations(out / name, cv2.cvtColor(small, cv2.COLOR_BGR2RGB), maps[:3], sal)
        written.append(name)
    result = {
        "model": str(model_path),
        "dataset": str(data_root),
        "lap": lap,
        "frames": len(rows),
        "rmse": round(rmse, 5),
        "max_abs_error": round(float(np.max(np.abs(pred - expert))), 5) if len(rows) else None,
        "figures": [f"lap_{lap}.png", *written],
    }
    (out / "analysis.json").write_text(json.dumps(result, indent=2) + "\n")
    log(f"lap {lap} RMSE {rmse:.4f}; figures in {out}")
    return result
