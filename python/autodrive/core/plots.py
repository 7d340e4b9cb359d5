"""Every PNG plot of the Python tools (matplotlib, Agg backend): the demo's trajectory, EKF
error and odometry plots, the parking plot, the parking sweep and the Eye benchmark."""

from __future__ import annotations

import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after choosing the backend)
import numpy as np  # noqa: E402
import numpy.typing as npt  # noqa: E402

from autodrive.core.geometry import Rect, rect_corners  # noqa: E402
from autodrive.core.runfiles import OccupancyMap  # noqa: E402

Floats = Sequence[float] | npt.NDArray[np.float64]
XY = tuple[Floats, Floats]
DPI = 110


def _save(fig: Any, path: Path | str, **kw: Any) -> None:
    """Writes through a temporary file, so a reader never sees half a PNG."""
    path = Path(path)
    tmp = path.with_name(path.name + ".tmp")
    fig.savefig(tmp, format="png", **kw)
    plt.close(fig)
    os.replace(tmp, path)


def trajectory(
    path: Path,
    vehicle_name: str,
    truth: XY,
    ekf: XY,
    path_length_m: float,
    rms: tuple[float, float],
) -> None:
    """trajectory.png: the EKF estimate (aligned at its start) over the ground truth; rms is
    (position [m], heading [deg])."""
    fig, ax = plt.subplots(figsize=(7, 6))
    ax.plot(truth[0], truth[1], "k-", lw=2, label="ground truth (sim)")
    ax.plot(ekf[0], ekf[1], "r--", lw=1, label="runtime EKF (wheel odometry + IMU)")
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(
        f"{vehicle_name} HIL drive: path {path_length_m} m, EKF RMS "
        f"{rms[0] * 100:.1f} cm / {rms[1]:.1f} deg"
    )
    ax.grid(True, alpha=0.3)
    ax.legend()
    fig.tight_layout()
    _save(fig, path, dpi=DPI)


def ekf_error(path: Path, t_s: Floats, pos_err_m: Floats, heading_err_deg: Floats) -> None:
    """ekf_error.png: EKF position and heading error over wall time."""
    fig, ax = plt.subplots(figsize=(7, 3))
    ax.plot(t_s, [e * 100 for e in pos_err_m], label="position error [cm]")
    ax.plot(t_s, heading_err_deg, label="heading error [deg]")
    ax.set_xlabel("time [s, wall]")
    ax.grid(True, alpha=0.3)
    ax.legend()
    fig.tight_layout()
    _save(fig, path, dpi=DPI)


ODOMETRY_STYLE = {
    "laser_odom": ("tab:blue", "laser odometry (ICP)"),
    "ekf_odom": ("tab:red", "EKF odometry (wheels + IMU)"),
}


def odometry(
    path: Path, truth: XY, tracks: Mapping[str, XY], drift_pct: Mapping[str, float | None]
) -> None:
    """odometry.png: laser and EKF dead reckoning against the truth over the same span."""
    fig, ax = plt.subplots(figsize=(7, 6))
    ax.plot(truth[0], truth[1], "k-", lw=2, label="ground truth")
    for name, (xs, ys) in tracks.items():
        colour, label = ODOMETRY_STYLE[name]
        pct = drift_pct.get(name)
        ax.plot(
            xs,
            ys,
            "--",
            color=colour,
            lw=1.2,
            label=f"{label}: {pct} % drift" if pct is not None else label,
        )
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title("dead reckoning from the same start, world frame")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    _save(fig, path, dpi=DPI)


@dataclass
class Layer:
    xs: Floats
    ys: Floats
    fmt: str
    style: dict[str, Any] = field(default_factory=dict)


def outline(r: Rect) -> XY:
    """A rectangle's closed outline."""
    pts = rect_corners(r)
    pts.append(pts[0])
    return [p[0] for p in pts], [p[1] for p in pts]


def parking(path: Path, occupancy: OccupancyMap, layers: Sequence[Layer]) -> None:
    """parking.png: left the whole saved map, right the same layers zoomed on the manoeuvre,
    where the centimetres are visible."""
    fig, axes = plt.subplots(1, 2, figsize=(16, 8.5))
    for ax in axes:
        ax.imshow(
            occupancy.image,
            cmap="gray",
            vmin=0,
            vmax=255,
            origin="upper",
            extent=occupancy.extent(),
        )
        seen: set[Any] = set()
        for layer in layers:
            kw = dict(layer.style)
            if kw.get("label") in seen:
                kw.pop("label", None)  # one legend entry per kind
            seen.add(kw.get("label"))
            ax.plot(layer.xs, layer.ys, layer.fmt, **kw)
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.set_aspect("equal")
    axes[0].set_title("saved map (whole)")
    xs = np.concatenate([np.asarray(la.xs, dtype=float) for la in layers] or [np.array([])])
    ys = np.concatenate([np.asarray(la.ys, dtype=float) for la in layers] or [np.array([])])
    xs, ys = xs[np.isfinite(xs)], ys[np.isfinite(ys)]
    if xs.size and ys.size:
        pad_m = 0.3
        cx, cy = (xs.min() + xs.max()) / 2, (ys.min() + ys.max()) / 2
        half = max(xs.max() - xs.min(), ys.max() - ys.min()) / 2 + pad_m
        axes[1].set_xlim(cx - half, cx + half)
        axes[1].set_ylim(cy - half, cy + half)
    axes[1].set_title("the manoeuvre (zoomed)")
    axes[1].legend(loc="best", fontsize=8)
    fig.suptitle("autonomous parking")
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    _save(fig, path, dpi=120, bbox_inches="tight")


@dataclass
class SweepBar:
    key: str  # per-seed figure
    scale: float  # to the plotted unit
    label: str
    unit: str
    goal: float  # in the plotted unit


@dataclass
class SweepRun:
    seed: int
    ok: bool
    world_track: XY | None  # ground truth in the world, None when missing
    goal_xy: tuple[float, float] | None


def sweep(
    path: Path,
    title: str,
    seeds: Sequence[int],
    ok: Sequence[bool],
    per_seed: Mapping[str, Sequence[float | None]],
    bars: Sequence[SweepBar],
    runs: Sequence[SweepRun],
) -> None:
    """parking_sweep.png: three per-seed bar charts with their goal lines, and every seed's
    ground-truth path in the world."""
    x = list(range(len(seeds)))
    colours = ["tab:blue" if o else "tab:red" for o in ok]
    fig, axs = plt.subplots(2, 2, figsize=(12, 9))
    for ax, bar in zip((axs[0][0], axs[0][1], axs[1][0]), bars):
        vals = [bar.scale * v if v is not None else 0.0 for v in per_seed[bar.key]]
        ax.bar(x, vals, color=colours)
        for xi, v in zip(x, per_seed[bar.key]):
            if v is None:
                ax.text(xi, 0, "no data", rotation=90, ha="center", va="bottom", fontsize=8)
        ax.axhline(
            bar.goal, color="tab:green", ls="--", lw=1.2, label=f"goal <= {bar.goal:g} {bar.unit}"
        )
        ax.set_xticks(x, [str(s) for s in seeds])
        ax.set_xlabel("seed")
        ax.set_ylabel(f"{bar.label} [{bar.unit}]")
        ax.legend(loc="upper right", fontsize=8)
    ax = axs[1][1]
    goals = set()
    for r in runs:
        if r.world_track and r.goal_xy:
            ax.plot(
                *r.world_track,
                "-",
                lw=1,
                color=None if r.ok else "tab:red",
                label=f"seed {r.seed}" + ("" if r.ok else " (failed)"),
            )
            goals.add((round(r.goal_xy[0], 4), round(r.goal_xy[1], 4)))
    for i, g in enumerate(sorted(goals)):
        ax.plot([g[0]], [g[1]], "kx", ms=10, label="goal (rear axle)" if i == 0 else None)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m] (world)")
    ax.set_ylabel("y [m] (world)")
    ax.set_title("ground-truth trajectories")
    if ax.lines:
        ax.legend(loc="best", fontsize=7)
    fig.suptitle(title)
    fig.tight_layout()
    _save(fig, path, dpi=DPI)


def eye_sim(path: Path, truth: XY, eye: XY, t_s: Floats, err_mm: Floats) -> None:
    """The Eye on the simulator's overhead camera: path and position error over time."""
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(12, 5))
    a1.plot(truth[0], truth[1], "-", color="0.6", lw=3, label="sim ground truth (base_link)")
    a1.plot(eye[0], eye[1], ".", ms=3, label="Eye")
    a1.set_aspect("equal")
    a1.set_xlabel("map x [m]")
    a1.set_ylabel("map y [m]")
    a1.set_title("autodrive-sim overhead camera (1280x960), NIGEL1")
    a1.legend(fontsize=8)
    a2.plot(t_s, err_mm, lw=1)
    a2.set_xlabel("sim time [s]")
    a2.set_ylabel("position error [mm]")
    a2.set_title("Eye vs ground truth")
    fig.tight_layout()
    _save(fig, path, dpi=DPI)


def eye_bench(path: Path, truth: XY, eye: XY, peer: XY) -> None:
    """The Eye benchmark's synthesised drive: truth, the Eye and the OpenCV aruco peer, and
    the position error per frame."""
    err_eye = [
        1000 * math.hypot(a - b, c - d) for a, b, c, d in zip(eye[0], truth[0], eye[1], truth[1])
    ]
    err_peer = [
        1000 * math.hypot(a - b, c - d) for a, b, c, d in zip(peer[0], truth[0], peer[1], truth[1])
    ]
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(13, 5), gridspec_kw={"width_ratios": [1.4, 1]})
    a1.plot(truth[0], truth[1], "-", color="0.6", lw=3, label="truth (base_link)")
    a1.plot(eye[0], eye[1], ".", color="tab:blue", ms=3, label="Eye (libapriltag, roof plane)")
    a1.plot(peer[0], peer[1], "x", color="tab:red", ms=2, alpha=0.5, label="peer (OpenCV aruco)")
    a1.set_xlabel("map x [m]")
    a1.set_ylabel("map y [m]")
    a1.set_aspect("equal")
    a1.set_title("Synthesised drive across the 3.0 x 2.0 m map, 1280x720")
    a1.legend(loc="upper right", fontsize=8)
    a2.plot(err_eye, color="tab:blue", lw=1, label="Eye")
    a2.plot(err_peer, color="tab:red", lw=1, alpha=0.6, label="peer (aruco)")
    a2.set_yscale("log")
    a2.set_xlabel("frame")
    a2.set_ylabel("position error [mm]")
    a2.set_title("Position error per frame")
    a2.legend(fontsize=8)
    fig.tight_layout()
    _save(fig, path, dpi=DPI)


def cloning_trace(
    path: Path,
    title: str,
    t_s: Sequence[float],
    steering: Sequence[float],
    offset_m: Sequence[float],
    half_width_m: float,
    wheel_margin_m: float,
    interventions_s: Sequence[float],
) -> None:
    """The cloning evaluation over time: the network's steering as the Nano took it, base_link's
    offset from the lane centre line (+ left) and the offsets at which a wheel's outer edge
    reaches the lane bound; interventions as red lines. Whether the car turns in early (cuts a
    curve: offset towards the inside) or late (runs wide) reads from it."""
    fig, (a0, a1) = plt.subplots(2, 1, figsize=(11, 5.5), sharex=True)
    a0.plot(t_s, steering, lw=0.8, color="tab:orange")
    a0.set_ylabel("steering (normalised, + left)")
    a1.plot(t_s, offset_m, lw=0.8, color="tab:blue", label="base_link offset")
    for sign in (1.0, -1.0):
        a1.axhline(sign * (half_width_m - wheel_margin_m), color="0.5", ls="--", lw=0.8)
    a1.set_ylabel("offset from the centre line [m] (+ left)")
    a1.set_xlabel("elapsed sim time [s]")
    for ax in (a0, a1):
        for t in interventions_s:
            ax.axvline(t, color="tab:red", lw=1.0)
        ax.grid(alpha=0.3)
    a1.legend(
        ["base_link offset", "a wheel's edge on the lane bound"], fontsize=8, loc="lower left"
    )
    a0.set_title(title, fontsize=9)
    _save(fig, path, dpi=DPI, bbox_inches="tight")


def cloning_laps(
    path: Path, title: str, centre: XY, bounds: Sequence[XY], driven: XY, interventions: XY
) -> None:
    """The cloning evaluation: the route's centre line and lane bounds, the driven path of
    base_link (ground truth), and where the car crossed a lane bound and was put back."""
    fig, ax = plt.subplots(figsize=(7.5, 7))
    for b in bounds:
        ax.plot(b[0], b[1], color="0.6", lw=0.8)
    ax.plot(centre[0], centre[1], "--", color="0.4", lw=0.8, label="lane centre line")
    ax.plot(driven[0], driven[1], color="tab:blue", lw=1.0, label="driven (ground truth)")
    if len(interventions[0]):
        ax.plot(interventions[0], interventions[1], "x", color="tab:red", ms=9, mew=2,
                label="intervention (wheel over the lane bound)")  # fmt: skip
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(title, fontsize=9)
    ax.legend(loc="center", fontsize=8)
    _save(fig, path, dpi=DPI, bbox_inches="tight")
