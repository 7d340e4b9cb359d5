"""tools/bench sim: simulator speed and fidelity. Progress on stderr; figures on stdout, the
last line one JSON object. Needs AUTODRIVE_BUILD (a release build).

rtf_N: median real-time factor of `autodrive-sim --lockstep` with N cars (1 kHz physics, the
emulated Nano of every car on its pty, IMU, LIDAR + RPLIDAR pty, ground truth on LCM);
bare_mj_step_rtf_N: a bare mj_step loop on the same model in the same process;
overhead_ratio = bare / rtf_1 (goal <= 1.11) and rtf_N_over_bare = rtf_N / bare (goal for 16
cars >= 0.85; rtf_16 >= 3), each taken within one run, medians over the runs. The *_cpu
variants divide by CPU time instead of wall time (the stepping thread's for the ratios: the
LCM sender has a thread of its own); on a shared, loaded machine they show the cost without
the waits. Since 2026-11-27 each lockstep run pairs every 1 s block of the sim's steps with a
1 s block of bare mj_step right after it (bench_pairs.h: both halves see the same load), and
bare_mj_step_rtf_N and the ratios come from those pairs (overhead_ratio_paired_N: the median of
the per-pair time ratios).
*_instructions: the same ratios in instructions per step, counted by valgrind's callgrind on a
short run (2 s with 1 car, 0.5 s with 16; sim_instructions.py): the load-independent figure.
rtf_1_two_cameras_30fps: one car with its front and rear cameras rendered and JPEG-published
at 30 Hz. turn_radius_error_pct: circle fitted to the ground truth at steering 0.6 vs
L/tan(delta); *_mujoco_friction: the same with plain MuJoCo contact friction instead of the
paper tyre model. goals_met: each goal by wall time and by CPU time. lidar_scan_us,
camera_fps_640x480: from the sensors library's sim-sensors-bench.
eye_render_ms_per_frame_1280x960: median process CPU time (llvmpipe's threads included) of one
overhead-camera frame of Tiny Town (4 cameras, one car driving in the view of each) with the
static world cached (sim_render_cache.h), and eye_render_full_ms_per_frame_1280x960 the full
render of the same frames in the same run (`autodrive-sim --eye-render compare`: each frame
rendered both ways), their ratio, the wall-clock medians (*_wall_*, load-dependent), how many
pixels differ (eye_render_differing_fraction, eye_render_max_abs_diff) and the load average
when it ran (eye_render_load_avg). Goals: <= 10 ms, and at most 1e-4 of the pixels differing.
viewer_fps, rtf_window_over_headless (goals >= 30, >= 0.8): the window with its HUD and Menu
Panel, 1 car in Tiny Town, against the same run headless (viewer()), with the median time of
each part of a frame (viewer_<part>_ms_median) at the default look and at others
(*_scale_1, *_scale_1_high, *_scale_1_ultra).
Options: SIM_BENCH_REPEATS (3).
"""

from __future__ import annotations

import math
import os
import shutil
import statistics
import struct
import subprocess
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from autodrive.core import lcmtypes, vehicle
from autodrive.bench import Progress, build_dir, last_json, print_figures, sim_instructions
from autodrive.core import seeds
from autodrive.bench.goals import Goal, at_least, at_most, judge

URL = "udpm://239.255.76.67:7731?ttl=0"  # sim's test/bench port range 7730-7759
CAR_COUNTS_AND_DURATIONS_S = ((1, 20), (4, 10), (16, 4))
DRIVE_SCRIPT = "constant:throttle=0.5,steering=0.3"
TURN_STEERINGS = (0.3, 0.6, 1.0)
TURN_SETTLE_US = 3e6  # skip the start of the circle
TOP_SPEED_SETTLE_US = 2e6
# one car in the view of each of Tiny Town's four overhead cameras (eye1..eye4)
EYE_RENDER_STARTS = ("1,-3.0,-3.14,0", "2,3.0,-3.14,180", "3,-3.0,2.86,0", "4,3.0,2.86,180")
EYE_RENDER_DURATION_S = 2.0  # 60 frame times x 4 cameras, each rendered cached and in full
EYE_RENDER_GOAL_MS = 10.0
# [s] sim time of each viewer run: free lockstep runs Tiny Town at rtf ~20-60 here, so 5-15 s
# of wall time, a few hundred frames
VIEWER_SIM_S = 300.0
EYE_RENDER_MAX_DIFFERING = 1e-4  # fraction of the pixels (tests/sim: sim.EyeRenderCache.*)
log = Progress("sim")


class SimBench:
    def __init__(self, build: Path) -> None:
        self.build = build
        self.sim = build / "bin" / "autodrive-sim"
        self.types = lcmtypes.load(build)
        car = vehicle.load()
        self.wheelbase_m = car.number("wheelbase_m")
        self.steer_limit_rad = car.number("steer_limit_rad")

    def run(self, args: Sequence[str], url: str) -> dict[str, Any]:
        with tempfile.TemporaryDirectory(prefix="bench-sim-") as run_dir:
            argv = [str(self.sim), "--quiet", "--bench", "--run-dir", run_dir, "--lcm-url", url]
            out = subprocess.run(
                argv + list(args), check=True, capture_output=True, text=True
            ).stdout
        return last_json(out, "autodrive-sim --bench")

    def pick_url(self) -> str:
        try:
            self.run(["--lockstep", "--duration", "0.05", "--no-pty"], URL)
            return URL
        except subprocess.CalledProcessError:
            log("udpm LCM unavailable (no multicast route?): using memq://, LCM cost not included")
            return "memq://"

    def truth_log(self, args: Sequence[str]) -> list[Any]:
        with tempfile.TemporaryDirectory(prefix="bench-sim-") as d:
            path = os.path.join(d, "truth.bin")
            argv = [str(self.sim), "--quiet", "--lockstep", "--no-pty", "--no-lidar"]
            argv += ["--lcm-url", "memq://", "--run-dir", d, "--truth-log", path]
            subprocess.run(argv + list(args), check=True, capture_output=True)
            data = open(path, "rb").read()
        msgs, i = [], 0
        while i < len(data):
            (n,) = struct.unpack(">I", data[i : i + 4])
            msgs.append(self.types.ground_truth_t.decode(data[i + 4 : i + 4 + n]))
            i += 4 + n
        return msgs

    def turn_error_pct(self, tyre: str, steering: float) -> float:
        script = f"constant:throttle=0.6,steering={steering}"
        msgs = self.truth_log(["--duration", "10", "--tyre-model", tyre, "--script", script])
        pts = [(m.position_m[0], m.position_m[1]) for m in msgs if m.utime > TURN_SETTLE_US]
        r = fit_radius([p[0] for p in pts], [p[1] for p in pts])
        expect = self.wheelbase_m / math.tan(steering * self.steer_limit_rad)
        return 100.0 * abs(r - expect) / expect

    def top_speed(self, tyre: str) -> float:
        script = "constant:throttle=1,steering=0"
        msgs = self.truth_log(["--duration", "5", "--tyre-model", tyre, "--script", script])
        v = [m.linear_velocity_m_s[0] for m in msgs if m.utime > TOP_SPEED_SETTLE_US]
        return float(sum(v) / len(v))


def fit_radius(xs: Sequence[float], ys: Sequence[float]) -> float:
    """Kasa least-squares circle: x^2 + y^2 + D x + E y + F = 0; its radius [m]."""
    x, y = np.asarray(xs, dtype=float), np.asarray(ys, dtype=float)
    a = np.column_stack([x, y, np.ones_like(x)])
    (d, e, f), *_ = np.linalg.lstsq(a, -(x * x + y * y), rcond=None)
    return math.sqrt(d * d / 4 + e * e / 4 - f)


def median(values: Sequence[float]) -> float:
    return round(statistics.median(values), 2)


def speed(bench: SimBench, url: str, repeats: int, res: dict[str, Any]) -> None:
    for cars, dur in CAR_COUNTS_AND_DURATIONS_S:
        runs = []
        for k in range(repeats):
            args = ["--lockstep", "--cars", str(cars), "--duration", str(dur)]
            r = bench.run(args + ["--script", DRIVE_SCRIPT], url)
            log(
                f"{cars} car(s), run {k + 1}/{repeats}: rtf {r['rtf']:.1f} (cpu "
                f"{r['rtf_cpu']:.1f}), bare mj_step {r['bare_mj_step_rtf']:.1f} "
                f"(cpu {r['bare_mj_step_rtf_cpu']:.1f})"
            )
            runs.append(r)
        res[f"rtf_{cars}"] = median([r["rtf"] for r in runs])
        res[f"rtf_cpu_{cars}"] = median([r["rtf_cpu"] for r in runs])
        res[f"rtf_step_thread_cpu_{cars}"] = median([r["rtf_step_thread_cpu"] for r in runs])
        res[f"bare_mj_step_rtf_{cars}"] = median([r["bare_mj_step_rtf"] for r in runs])
        res[f"bare_mj_step_rtf_cpu_{cars}"] = median([r["bare_mj_step_rtf_cpu"] for r in runs])
        # ratios within one run (the same load on the machine), then their median
        ratios = [r["bare_mj_step_rtf"] / r["rtf"] for r in runs]
        ratios_cpu = [r["bare_mj_step_rtf_cpu"] / r["rtf_step_thread_cpu"] for r in runs]
        if "overhead_ratio_paired" in runs[0]:
            res[f"overhead_ratio_paired_{cars}"] = round(
                statistics.median([r["overhead_ratio_paired"] for r in runs]), 3
            )
        if cars == 1:
            res["overhead_ratio"] = round(statistics.median(ratios), 3)
            res["overhead_ratio_cpu"] = round(statistics.median(ratios_cpu), 3)
        else:
            res[f"rtf_{cars}_over_bare"] = round(statistics.median([1 / q for q in ratios]), 3)
            res[f"rtf_{cars}_over_bare_cpu"] = round(
                statistics.median([1 / q for q in ratios_cpu]), 3
            )
    try:
        args = ["--lockstep", "--cameras", "--duration", "3", "--script", DRIVE_SCRIPT]
        rtfs = [bench.run(args, url)["rtf"] for _ in range(repeats)]
        res["rtf_1_two_cameras_30fps"] = median(rtfs)
        log(f"two cameras at 30 fps: rtf {rtfs}")
    except subprocess.CalledProcessError as e:
        log(f"cameras unavailable: {e.stderr.strip() if e.stderr else e}")


def eye_render(bench: SimBench, url: str, res: dict[str, Any]) -> None:
    """The overhead cameras: cached and full render of the same frames, in one run."""
    args = ["--lockstep", "--no-pty", "--map", "tiny_town", "--cars", "4", "--eye"]
    for start in EYE_RENDER_STARTS:
        args += ["--car-start", start]
    args += ["--eye-render", "compare", "--script", DRIVE_SCRIPT]
    args += ["--duration", str(EYE_RENDER_DURATION_S)]
    load = os.getloadavg()[0]
    try:
        r = bench.run(args, url)
    except subprocess.CalledProcessError as e:
        log(f"overhead cameras unavailable: {e.stderr.strip() if e.stderr else e}")
        return
    cached, full = r["eye_render_cpu_ms_median"], r["eye_render_full_cpu_ms_median"]
    res["eye_render_ms_per_frame_1280x960"] = round(cached, 3)
    res["eye_render_full_ms_per_frame_1280x960"] = round(full, 3)
    res["eye_render_ratio"] = round(cached / full, 4) if full > 0 else None
    res["eye_render_wall_ms_per_frame_1280x960"] = round(r["eye_render_wall_ms_median"], 3)
    res["eye_render_full_wall_ms_per_frame_1280x960"] = round(
        r["eye_render_full_wall_ms_median"], 3
    )
    res["eye_render_frames"] = r["eye_render_frames"]
    res["eye_render_differing_fraction"] = r["eye_render_differing_fraction"]
    res["eye_render_max_abs_diff"] = r["eye_render_max_abs_diff"]
    res["eye_render_load_avg"] = round(load, 1)
    log(
        f"overhead cameras (Tiny Town, {r['eye_render_frames']} frames, load {load:.1f}): "
        f"cached {cached:.2f} ms, full {full:.2f} ms of CPU per frame (median); "
        f"{r['eye_render_differing_fraction']:.2g} of the pixels differ"
    )


def instructions(bench: SimBench, res: dict[str, Any]) -> None:
    if not sim_instructions.available():
        log("valgrind not installed: no instruction counts")
        return
    for cars, dur in ((1, 2.0), (16, 0.5)):
        log(f"{cars} car(s): counting instructions per step under callgrind ({dur:g} s sim)")
        args = ["--cars", str(cars), "--script", DRIVE_SCRIPT]
        n = sim_instructions.measure(bench.sim, args, dur)
        res[f"instructions_per_step_{cars}"] = round(n.sim_per_step)
        res[f"bare_instructions_per_step_{cars}"] = round(n.bare_per_step)
        if cars == 1:
            res["overhead_ratio_instructions"] = round(n.overhead_ratio, 4)
        else:
            res[f"rtf_{cars}_over_bare_instructions"] = round(1.0 / n.overhead_ratio, 4)


def fidelity(bench: SimBench, res: dict[str, Any]) -> None:
    for tyre, suffix in (("paper", ""), ("mujoco", "_mujoco_friction")):
        errs = [bench.turn_error_pct(tyre, s) for s in TURN_STEERINGS]
        res["turn_radius_error_pct" + suffix] = round(max(errs), 3)
        res["top_speed_m_s" + suffix] = round(bench.top_speed(tyre), 4)
        log(
            f"tyre model {tyre}: turn radius error at steering 0.3/0.6/1.0 = "
            f"{', '.join(f'{e:.2f}' for e in errs)} %, top speed "
            f"{res['top_speed_m_s' + suffix]} m/s"
        )


def sensors(build: Path, res: dict[str, Any]) -> None:
    sensors_bench = build / "bin" / "sim-sensors-bench"
    if not os.access(sensors_bench, os.X_OK):
        log("sim-sensors-bench not built: no lidar/camera figures")
        return
    log("running sim-sensors-bench (sensors library)")
    try:
        out = subprocess.run(
            [str(sensors_bench)], check=True, capture_output=True, text=True
        ).stdout
        s = last_json(out, "sim-sensors-bench")
        for k in ("lidar_scan_us", "camera_fps_640x480"):
            if k in s:
                res[k] = s[k]
    except (subprocess.CalledProcessError, ValueError) as e:
        log(f"sim-sensors-bench failed, no lidar/camera figures: {e}")


VIEWER_PARTS = ("update", "scene", "blit", "thumbs", "hud", "ui", "swap")  # sim_viewer_part_t
# (name, extra autodrive-sim arguments): the breakdown's other looks, one window run each
VIEWER_LOOKS = (
    ("nice_0", ["--view-nice", "0"]),  # the window's threads at the stepping's priority
    ("scale_1", ["--view-scale", "1"]),
    ("scale_1_high", ["--view-scale", "1", "--view-quality", "high"]),
    ("scale_1_ultra", ["--view-scale", "1", "--view-quality", "ultra"]),
)


def _viewer_figures(r: dict[str, Any], suffix: str, res: dict[str, Any]) -> None:
    res["viewer_fps" + suffix] = r["viewer_fps"]
    res["viewer_frame_ms_median" + suffix] = r["viewer_frame_ms_median"]
    for part in VIEWER_PARTS:
        res[f"viewer_{part}_ms_median{suffix}"] = r[f"viewer_{part}_ms_median"]


def viewer(bench: SimBench, url: str, repeats: int, res: dict[str, Any]) -> None:
    """The window (issue 36): 1 car in Tiny Town in free lockstep, headless and then with --view
    (HUD and Menu Panel on) on an Xvfb of its own, back to back, repeats times; then one window
    run per other look (VIEWER_LOOKS) for the breakdown. viewer_fps = 1 / the median wall time
    to draw a frame (the rate the window can keep; it draws at most 30 Hz of wall time, from
    snapshots: viewer_fps_drawn is the rate it drew); rtf_window_over_headless = rtf with the
    window / rtf headless within each pair, their median. --bench times each part of a frame
    (each ended by glFinish: viewer_<part>_ms_median). Xvfb renders with Mesa's llvmpipe on the
    CPU: on a laptop's GPU the window costs far less."""
    if not shutil.which("Xvfb"):
        log("viewer: Xvfb missing (tools/debian-packages.txt): viewer figures left out")
        return
    display = f":{400 + os.getpid() % 500}"
    xvfb = subprocess.Popen(
        ["Xvfb", display, "-screen", "0", "1280x1024x24", "-nolisten", "tcp"],
        stderr=subprocess.DEVNULL,
    )
    res["viewer_load_avg_start"] = round(os.getloadavg()[0], 1)
    args = ["--lockstep", "--map", "tiny_town", "--no-pty", "--duration", str(VIEWER_SIM_S)]
    headless, window, looks = [], [], {}
    try:
        sock = Path(f"/tmp/.X11-unix/X{display[1:]}")
        for _ in range(300):  # readiness, not a timing figure
            if sock.exists():
                break
            time.sleep(0.05)
        for k in range(repeats):
            # unpaired like the window's run (never paired): a like-for-like baseline
            headless.append(bench.run(args + ["--bench-unpaired"], url))
            os.environ["DISPLAY"] = display
            try:
                window.append(bench.run(args + ["--view"], url))
                if k == 0:
                    looks = {name: bench.run(args + ["--view"] + extra, url)
                             for name, extra in VIEWER_LOOKS}  # fmt: skip
            finally:
                del os.environ["DISPLAY"]
            w = window[-1]
            log(
                f"viewer run {k + 1}/{repeats}: headless rtf {headless[-1]['rtf']:.1f}, window "
                f"rtf {w['rtf']:.1f}; {w['viewer_fps']:.1f} fps ({w['viewer_frame_ms_median']:.1f}"
                f" ms a frame, {w['viewer_fps_drawn']:.1f} drawn), scale "
                f"{w['viewer_render_scale']}, {w['viewer_renderer']}"
            )
    finally:
        xvfb.terminate()
        xvfb.wait()
    mid = sorted(window, key=lambda r: r["viewer_fps"])[len(window) // 2]
    _viewer_figures(mid, "", res)
    res["viewer_fps_drawn"] = median([r["viewer_fps_drawn"] for r in window])
    res["viewer_frames"] = mid["viewer_frames"]
    res["viewer_steps_while_drawing"] = mid["viewer_steps_while_drawing"]
    res["viewer_render_scale"] = mid["viewer_render_scale"]
    res["viewer_renderer"] = mid["viewer_renderer"]
    for name, r in looks.items():
        _viewer_figures(r, "_" + name, res)
        log(f"viewer {name}: {r['viewer_fps']:.1f} fps, scene {r['viewer_scene_ms_median']} ms")
    res["rtf_1_tiny_town_headless"] = median([r["rtf"] for r in headless])
    res["rtf_1_tiny_town_window"] = median([r["rtf"] for r in window])
    ratios = [w["rtf"] / h["rtf"] for w, h in zip(window, headless)]
    res["rtf_window_over_headless"] = round(statistics.median(ratios), 3)
    res["viewer_load_avg"] = round(os.getloadavg()[0], 1)


def goal_table() -> dict[str, Goal]:
    """The issue's speed goals, by wall time, by CPU time (a loaded machine) and in instructions
    (callgrind), and the sensor and fidelity goals."""
    goals: dict[str, Goal] = {}
    for suffix in ("", "_cpu", "_instructions"):
        goals["overhead_ratio" + suffix] = at_most("overhead_ratio" + suffix, 1.11)
        goals["rtf_16_over_bare" + suffix] = at_least("rtf_16_over_bare" + suffix, 0.85)
    goals.update(
        rtf_4=at_least("rtf_4", 10.0),
        rtf_16=at_least("rtf_16", 3.0),
        rtf_cpu_16=at_least("rtf_cpu_16", 3.0),
        rtf_1_two_cameras_30fps=at_least("rtf_1_two_cameras_30fps", 2.0),
        lidar_scan_us=at_most("lidar_scan_us", 200.0),
        camera_fps_640x480=at_least("camera_fps_640x480", 100.0),
        turn_radius_error_pct=at_most("turn_radius_error_pct", 1.0),
        eye_render_ms_per_frame_1280x960=at_most(
            "eye_render_ms_per_frame_1280x960", EYE_RENDER_GOAL_MS
        ),
        viewer_fps=at_least("viewer_fps", 30.0),
        rtf_window_over_headless=at_least("rtf_window_over_headless", 0.8),
        eye_render_equals_full_render=at_most(
            "eye_render_differing_fraction", EYE_RENDER_MAX_DIFFERING
        ),
    )
    return goals


GOALS = goal_table()
UNSEEDED = seeds.unseeded("speed and fidelity of scripted runs, the same whatever the seed")


def main(argv: list[str]) -> int:
    if argv:
        print(__doc__.strip())
        return 0 if argv[0] in ("-h", "--help") else 2
    build = build_dir("sim")
    bench = SimBench(build)
    repeats = int(os.environ.get("SIM_BENCH_REPEATS", "3"))
    res: dict[str, Any] = {}
    url = bench.pick_url()
    speed(bench, url, repeats, res)
    eye_render(bench, url, res)
    viewer(bench, url, repeats, res)
    instructions(bench, res)
    fidelity(bench, res)
    sensors(build, res)
    res["lcm_url"] = url
    print_figures(judge(res, GOALS, UNSEEDED), key_value_lines=True)
    return 0
