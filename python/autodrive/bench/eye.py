"""tools/bench eye: the Eye's whole pipeline (JPEG decode, libapriltag detection, roof-plane
pose, LCM publish) on one thread, and OpenCV's aruco (DICT_APRILTAG_36h11) as the peer on the
same frames, over a synthesised drive across the whole map (bin/eye_bench); then, when
autodrive-sim is built, the Eye on the simulator's overhead camera against its ground truth
(sim_* keys, autodrive.bench.eye_sim). The *_wide_angle keys: a barrel lens (k1 -0.30,
k2 0.10), dim light, vignetting, noise sigma 6, 10 cars with 18-40 px tags over the whole image,
edges included; the Eye (whole-field plan) against the previous default (decimate-2 scans) and
decimate 1 everywhere in the same run (fps ratios), with and without window tracking; and a
camera bumped by 5 mm / 0.3 deg (bumped_camera_*; sim_bumped_camera_*: the same on the
simulator's frames of Tiny Town, autodrive.bench.eye_multi --bump). The cameras of Tiny
Town are calibrated from its reference tags by calibrate-map first (refcal_*: residuals, how
neighbours agree on shared tags; autodrive.bench.eye_refcal). handover_gap_frames and
sim_multi_cam_*: Tiny Town's four overhead cameras rendered by the simulator as one Eye, a car
driving a lap through their overlaps (autodrive.bench.eye_multi). capture_to_pose_ms_*:
a running autodrive-eye fed the wide-angle scene's 720p frames (10 cars) at 30 Hz over LCM,
from each frame's capture stamp to the last of its poses on LCM
(autodrive.bench.eye_latency; wall clock, so the machine's load is printed with it).
Speeds are medians over passes; fps_* are wall-clock, fps_*_cpu divide by the thread's CPU
time instead (the machine is shared). Writes out/bench/eye_trajectory
{.csv,.png}, eye_sim_trajectory{.csv,.png} and eye_multi_cam{.csv,.png}. Progress on stderr;
last line one JSON object. Options: EYE_BENCH_FRAMES (240), EYE_BENCH_REPEATS (3),
EYE_BENCH_SIM_S (30, 0: skip), EYE_BENCH_MULTI_S (140, 0: skip), EYE_BENCH_LATENCY_FRAMES
(300, 0: skip), EYE_BENCH_BUMP (1, 0: skip)."""

from __future__ import annotations

import math
import os
import subprocess
from pathlib import Path
from typing import Any

from autodrive.core import plots
from autodrive.core.runfiles import read_columns
from autodrive.bench import (
    Progress,
    build_dir,
    eye_latency,
    eye_multi,
    eye_sim,
    out_dir,
    print_figures,
)
from autodrive.core import seeds
from autodrive.bench.goals import at_least, at_most, equals, judge

UNSEEDED = seeds.unseeded("fixed synthesised scenes and simulator runs: speeds and pose errors")
# The Eye's goals (every part of the suite: a part skipped by its option fails its goals)
GOALS = {
    "fps_720p": at_least("fps_1280x720_1t", 60),
    "fps_1080p": at_least("fps_1920x1080_1t", 25),
    "pos_rms": at_most("pos_rms_mm", 5),
    "heading_rms": at_most("heading_rms_deg", 0.5),
    "detect_rate": at_least("detect_rate", 0.99),
    "detect_rate_wide_angle": at_least("detect_rate_wide_angle", 0.995),
    "pos_rms_wide_angle": at_most("pos_rms_mm_wide_angle", 1.0),
    "heading_rms_wide_angle": at_most("heading_rms_deg_wide_angle", 0.3),
    "fps_720p_wide_angle": at_least("fps_1280x720_1t_wide_angle", 60),
    "bumped_camera_detected": equals("bumped_camera_detected", True),
    "capture_to_pose_p99": at_most("capture_to_pose_ms_p99", 15),
}
INT_KEYS = ("frames", "repeats")
BOOL_KEYS = (  # measured as 0 / 1
    "bumped_camera_detected",
    "unmoved_camera_no_alarm",
    "sim_bumped_camera_detected",
    "sim_unmoved_cameras_no_alarm",
)
log = Progress("eye")


def key_values(text: str) -> dict[str, float]:
    """ "key value" lines as a dict."""
    out = {}
    for line in text.splitlines():
        if line.strip():
            k, v = line.split()
            out[k] = float(v)
    return out


def plot(csv: Path, png: Path) -> None:
    cols = ["true_x_m", "true_y_m", "eye_x_m", "eye_y_m", "peer_x_m", "peer_y_m"]
    c = read_columns(csv, cols, missing=math.nan)
    plots.eye_bench(
        png,
        (c["true_x_m"], c["true_y_m"]),
        (c["eye_x_m"], c["eye_y_m"]),
        (c["peer_x_m"], c["peer_y_m"]),
    )


def main(argv: list[str]) -> int:
    if argv:
        print(__doc__.strip())
        return 0 if argv[0] in ("-h", "--help") else 2
    build = build_dir("eye")
    out = out_dir()
    csv, png = out / "eye_trajectory.csv", out / "eye_trajectory.png"
    frames, repeats = os.environ.get("EYE_BENCH_FRAMES", "240"), os.environ.get(
        "EYE_BENCH_REPEATS", "3"
    )
    log(f"eye_bench: {frames} frames, {repeats} passes")
    text = subprocess.run(
        [build / "bin" / "eye_bench", "--frames", frames, "--repeats", repeats, "--csv", csv],
        check=True,
        stdout=subprocess.PIPE,
        text=True,
    ).stdout
    figures = key_values(text)
    latency_frames = int(os.environ.get("EYE_BENCH_LATENCY_FRAMES", "300"))
    if latency_frames > 0:
        log(f"capture to pose on LCM: {latency_frames} frames at 30 Hz into autodrive-eye")
        try:
            figures.update(eye_latency.measure(build, latency_frames, 30.0))
            # the same at ordinary priority: what SCHED_FIFO buys on this machine
            ordinary = eye_latency.measure(build, latency_frames, 30.0, realtime_priority=0)
            for q in ("p50", "p99"):
                figures[f"capture_to_pose_ordinary_ms_{q}"] = ordinary[f"capture_to_pose_ms_{q}"]
        except RuntimeError as e:
            log(f"capture to pose failed: {e}")
    # (option, default sim seconds, what, measure, output prefix) of each simulator run
    sim_runs = (
        ("EYE_BENCH_SIM_S", "30", "simulator overhead camera", eye_sim.measure, "eye_sim_trajectory"),
        ("EYE_BENCH_MULTI_S", "140", "Tiny Town's cameras as one Eye, a lap", eye_multi.measure,
         "eye_multi_cam"),
    )  # fmt: skip
    for option, default, what, measure, prefix in sim_runs:
        sim_s = float(os.environ.get(option, default))
        if sim_s == 0:
            continue
        if not os.access(build / "bin" / "autodrive-sim", os.X_OK):
            log(f"autodrive-sim not built: no {what} figures")
            continue
        log(f"{what}, {sim_s:g} s")
        try:
            figures.update(measure(build, sim_s, str(out / prefix)))
        except RuntimeError as e:
            log(f"{what} failed: {e}")
    if os.environ.get("EYE_BENCH_BUMP", "1") != "0" and os.access(
        build / "bin" / "autodrive-sim", os.X_OK
    ):
        log("a bumped camera on the simulator's frames (eye1 moved 5 mm / 0.3 deg)")
        try:
            figures.update(eye_multi.bumped_camera(build))
        except RuntimeError as e:
            log(f"bumped camera run failed: {e}")
    for k, v in figures.items():
        print(f"{k} {v}")
    try:
        plot(csv, png)
        log(f"plot {png}")
    except ValueError as e:
        log(f"plot failed: {e}")
    typed: dict[str, Any] = {
        k: int(v) if k in INT_KEYS else bool(v) if k in BOOL_KEYS else v for k, v in figures.items()
    }
    print_figures(judge(typed, GOALS, UNSEEDED))
    return 0
