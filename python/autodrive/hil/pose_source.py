"""Where the HIL missions' cars get their absolute poses (`--eye`), and how good their EKFs were.

- `cameras` (default): autodrive-eye on the simulator's rendered overhead cameras (the map's
  eye_cameras, or Parking School's one `eye` camera), as in the lab; report `pose_source` "eye".
  In a lockstep run the Eye is in lockstep too (`autodrive-sim --eye-sync`, `autodrive-eye run
  --sim-latency-ms L`, L from `--eye-latency-ms`): a frame captured at t has its poses on the
  bus at t + L of sim time whatever the host's load; the report says L (`eye_latency_ms`).
  The sim gives a silent Eye up after `--eye-sync-wait-s` of wall time (a hang guard); a run
  where that happened depended on wall time, so every give-up is counted from the sim's log
  (`eye_sync_give_ups`, per run) and any fails the mission (`eye_sync_verdict`).
- `standin`: the test double autodrive.hil.city.eye_standin (ground truth + the Eye's noise, at
  once, never late, never missing); `pose_source` "standin".
- `none`: no absolute poses; each EKF starts from the pose the car was put down at, given with
  its placement uncertainty, and dead-reckons; `pose_source` "none".

No EKF is ever given the simulator's truth: with an Eye it starts from its first fix (the
runtime publishes no map pose until then and its driver holds the car still).

`PoseRecord` keeps, per car, the ground truth, the EKF's map poses and the Eye poses of a run,
and reports Eye poses per car per second of sim time and the EKF error against the truth."""

from __future__ import annotations

import argparse
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np

from autodrive.core.proc import ProcessGroup
from autodrive.maps import eye_cameras

EYE_CHOICES = ("cameras", "standin", "none")
POSE_SOURCE = {"cameras": "eye", "standin": "standin", "none": "none"}  # report's pose_source
EYE_FPS_DEFAULT = 5.0  # the overhead cameras' frame rate [Hz of sim time] unless --cameras
# --eye none: how far the operator may have put a car from its marked start (1 sigma), what
# its EKF is told with the pose (estimator.initial_pos_std_m, initial_yaw_std_rad).
PLACEMENT_STD_M = 0.02
PLACEMENT_STD_RAD = 0.035  # 2 deg
# The Eye's capture-to-pose time in a lockstep run [ms of sim time]: `tools/bench eye`'s
# capture_to_pose_ms_p99 at ordinary priority, 14.95 ms (docs/results/benchmarks.md,
# 2026-11-28), which is also that bench's goal (<= 15 ms).
EYE_LATENCY_MS_DEFAULT = 15.0
EYE_LATENCY_FROM = "tools/bench eye capture_to_pose_ms_p99 (14.95 ms, docs/results/benchmarks.md)"
# autodrive-sim --eye-sync's hang guard [s of wall time]: a silent Eye is given up after this
# (its EYE_SYNC_LOST_S), and each give-up is a line of its stderr with this mark (eye_sync.h's
# EYE_SYNC_GIVE_UP_MARK; tests/eye/test_sim_eye_give_up.py runs the two together).
EYE_SYNC_WAIT_S_DEFAULT = 10.0
EYE_SYNC_GIVE_UP_MARK = "--eye-sync gave up on the Eye"


def add_eye_option(p: argparse.ArgumentParser, default: str | None = "cameras") -> None:
    """--eye cameras|standin|none (the one pose-source flag of every mission)."""
    p.add_argument(
        "--eye",
        choices=EYE_CHOICES,
        default=default,
        help="the cars' absolute poses: cameras (default): autodrive-eye on the simulator's "
        "rendered overhead cameras (--cameras FPS sets their rate; default "
        f"{EYE_FPS_DEFAULT:g} Hz of sim time), each EKF started from its first Eye fix; standin: "
        "the test double (ground truth + the Eye's noise, city.eye_standin); none: no Eye, each "
        "EKF starts from the car's marked start pose with its placement uncertainty "
        f"({PLACEMENT_STD_M * 100:g} cm, {np.degrees(PLACEMENT_STD_RAD):.0f} deg) and "
        "dead-reckons",
    )
    p.add_argument(
        "--eye-latency-ms",
        type=ranged_arg(0.0, 10000.0, "ms"),  # as autodrive-eye accepts
        default=EYE_LATENCY_MS_DEFAULT,
        metavar="L",
        help="(--eye cameras, lockstep runs) the Eye's capture-to-pose time [ms of sim time]: "
        "the simulator never runs past a frame's capture time + L before the Eye has published "
        "its poses, so results do not depend on the host's load; default "
        f"{EYE_LATENCY_MS_DEFAULT:g}, {EYE_LATENCY_FROM}",
    )
    p.add_argument(
        "--eye-sync-wait-s",
        type=ranged_arg(0.1, 3600.0, "s"),  # as autodrive-sim accepts
        default=EYE_SYNC_WAIT_S_DEFAULT,
        metavar="S",
        help="(--eye cameras, lockstep runs) a hang guard: the simulator gives a silent Eye up "
        "after S s of wall time and runs on without waiting for it. A run where that happened "
        "depended on the host's load, so each give-up is counted (report: eye_sync_give_ups) "
        f"and fails the mission; default {EYE_SYNC_WAIT_S_DEFAULT:g}",
    )


def ranged_arg(low: float, high: float, unit: str) -> Callable[[str], float]:
    """An argparse type for a number in low..high [unit], bounded as the program it is passed to
    (autodrive-sim, autodrive-eye) accepts it, so a bad value is named here rather than there."""

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r}: want a number of {unit}") from None
        if not low <= value <= high:
            raise argparse.ArgumentTypeError(f"{text}: want {low:g}..{high:g} {unit}")
        return value

    return parse


def lockstep_latency_ms(args: argparse.Namespace, lockstep: bool) -> float | None:
    """The Eye's lockstep latency of a run [ms of sim time]: --eye-latency-ms when the real Eye
    runs and the simulator is in a lockstep mode; None otherwise (paced runs: the Eye keeps up
    or falls behind, as a real one)."""
    return float(args.eye_latency_ms) if lockstep and args.eye == "cameras" else None


def estimator_start(
    cfg: dict[str, Any], eye: str, marked_start: tuple[float, float, float]
) -> None:
    """Sets a runtime config's estimator start for --eye: with an Eye nothing (the first fix
    places the car); without one the marked start pose with its placement uncertainty."""
    est = cfg["estimator"]
    for key in ("initial_pose_map", "initial_pos_std_m", "initial_yaw_std_rad"):
        est.pop(key, None)
    if eye == "none":
        est["initial_pose_map"] = [float(v) for v in marked_start]
        est["initial_pos_std_m"] = PLACEMENT_STD_M
        est["initial_yaw_std_rad"] = PLACEMENT_STD_RAD


def placed(
    marked: list[tuple[float, float, float]], eye: str, seed: int
) -> list[tuple[float, float, float]]:
    """Where the simulator puts each car down: at its marked start, or (--eye none, where the
    EKF is told the marked start) off it by a seeded placement error of PLACEMENT_STD_M and
    PLACEMENT_STD_RAD, as an operator's hands would, so the EKF never starts on the truth."""
    if eye != "none":
        return list(marked)
    rng = np.random.default_rng(seed + 7919)
    return [
        (
            x + float(rng.normal(0.0, PLACEMENT_STD_M)),
            y + float(rng.normal(0.0, PLACEMENT_STD_M)),
            yaw + float(rng.normal(0.0, PLACEMENT_STD_RAD)),
        )
        for x, y, yaw in marked
    ]


def percentiles_m(errors: list[float]) -> dict[str, float] | None:
    """p50, p95 and max of errors [m], rounded to 0.1 mm; None without any."""
    if not errors:
        return None
    a = np.asarray(errors)
    return {
        "p50": round(float(np.percentile(a, 50)), 4),
        "p95": round(float(np.percentile(a, 95)), 4),
        "max": round(float(a.max()), 4),
    }


@dataclass
class PoseRecord:
    """One run's poses per car: truth and EKF as (t [s sim], x [m], y [m]), Eye pose counts."""

    truth: dict[str, list[tuple[float, float, float]]] = field(default_factory=dict)
    ekf: dict[str, list[tuple[float, float, float]]] = field(default_factory=dict)
    eye_poses: dict[str, int] = field(default_factory=dict)
    first_fix_s: dict[str, float] = field(default_factory=dict)  # the first Eye pose [s sim]

    def on_truth(self, car: str, t_s: float, x_m: float, y_m: float) -> None:
        self.truth.setdefault(car, []).append((t_s, x_m, y_m))

    def on_ekf(self, car: str, t_s: float, x_m: float, y_m: float) -> None:
        self.ekf.setdefault(car, []).append((t_s, x_m, y_m))

    def on_eye(self, car: str, t_s: float) -> None:
        self.eye_poses[car] = self.eye_poses.get(car, 0) + 1
        self.first_fix_s.setdefault(car, t_s)

    def errors_m(self, car: str) -> list[float]:
        """The car's EKF map poses against the truth at the same sim time (interpolated between
        the truth's samples, inside their span only) [m]."""
        truth = np.array(self.truth.get(car, []))
        est = np.array(self.ekf.get(car, []))
        if len(truth) < 2 or len(est) == 0:
            return []
        est = est[(est[:, 0] >= truth[0, 0]) & (est[:, 0] <= truth[-1, 0])]
        x = np.interp(est[:, 0], truth[:, 0], truth[:, 1])
        y = np.interp(est[:, 0], truth[:, 0], truth[:, 2])
        return [float(e) for e in np.hypot(est[:, 1] - x, est[:, 2] - y)]

    def sim_span_s(self, car: str) -> float:
        tr = self.truth.get(car, [])
        return tr[-1][0] - tr[0][0] if len(tr) >= 2 else 0.0


def report(
    eye: str,
    what: str,
    records: list[PoseRecord],
    cars: list[str],
    latency_ms: float | None = None,
    give_ups: int | None = None,
) -> dict[str, Any]:
    """The report's pose fields over one or more runs (episodes): pose_source, what ran, the
    Eye's lockstep latency [ms of sim time] (None: not in lockstep) and how often the sim gave
    the Eye up (give_ups, eye_sync_give_ups: None when not in lockstep), Eye poses per car per
    second of sim time, each car's EKF error against the truth (p50, p95, max [m]) and the
    worst car's p95, and when each car's first Eye fix came [s sim]."""
    rate: dict[str, float] = {}
    err: dict[str, dict[str, float] | None] = {}
    for car in cars:
        span = sum(r.sim_span_s(car) for r in records)
        n = sum(r.eye_poses.get(car, 0) for r in records)
        rate[car] = round(n / span, 2) if span > 0 else 0.0
        err[car] = percentiles_m([e for r in records for e in r.errors_m(car)])
    p95 = [e["p95"] for e in err.values() if e]
    fixes = [r.first_fix_s for r in records]
    return {
        "pose_source": POSE_SOURCE[eye],
        "eye": what,
        "eye_latency_ms": latency_ms if eye == "cameras" else None,
        "eye_sync_give_ups": give_ups if eye == "cameras" and latency_ms is not None else None,
        "eye_poses_per_car_hz": rate,
        "ekf_error_m": err,
        "ekf_error_p95_worst_m": max(p95) if p95 else None,
        "first_eye_fix_s": (
            {c: round(fixes[0][c], 2) for c in cars if c in fixes[0]} if len(fixes) == 1 else None
        ),
    }


def summary_line(rep: dict[str, Any]) -> str:
    """The human-readable pose summary of a report."""
    err = rep.get("ekf_error_m") or {}
    cars = ", ".join(
        f"{c} p50 {e['p50'] * 100:.1f} / p95 {e['p95'] * 100:.1f} / max {e['max'] * 100:.1f} cm"
        if e
        else f"{c} no EKF map pose"
        for c, e in sorted(err.items())
    )
    hz = ", ".join(f"{c} {v:g}" for c, v in sorted(rep.get("eye_poses_per_car_hz", {}).items()))
    return (
        f"poses from {rep.get('pose_source')} ({rep.get('eye')}); Eye poses per car per s of sim "
        f"time: {hz or '-'}; EKF error against ground truth: {cars or '-'}"
    )


def sim_argv(
    eye: str, fps: float, latency_ms: float | None, wait_s: float = EYE_SYNC_WAIT_S_DEFAULT
) -> list[object]:
    """autodrive-sim's options for --eye: cameras renders the map's overhead cameras at fps
    [Hz of sim time]; with latency_ms (a lockstep run) in lockstep with the Eye (--eye-sync),
    a silent Eye given up after wait_s [s wall]."""
    if eye != "cameras":
        return []
    return ["--eye", "--camera-fps", fps, *sim_sync_argv(latency_ms, wait_s)]


def sim_sync_argv(latency_ms: float | None, wait_s: float) -> list[object]:
    """autodrive-sim's lockstep with the Eye (none when latency_ms is None: not in lockstep)."""
    return [] if latency_ms is None else ["--eye-sync", "--eye-sync-wait-s", wait_s]


def eye_sync_give_ups(sim_log: Path, latency_ms: float | None) -> int | None:
    """How often autodrive-sim gave the Eye up in a run, from its log (each give-up is a line
    with EYE_SYNC_GIVE_UP_MARK, also with --quiet); None when the run was not in lockstep with
    the Eye (latency_ms None). A log that cannot be read counts as -1: unknown, a failure."""
    if latency_ms is None:
        return None
    try:
        text = sim_log.read_text(errors="replace")
    except OSError:
        return -1
    return sum(EYE_SYNC_GIVE_UP_MARK in line for line in text.splitlines())


def eye_sync_failure(give_ups: int | None, runs: int = 1) -> str | None:
    """The message that fails a mission whose sim gave the Eye up (give_ups > 0, over runs
    runs) or whose count is unknown (< 0); None when it never did or was not in lockstep."""
    if give_ups is None or give_ups == 0:
        return None
    if give_ups < 0:
        return (
            "eye_sync_give_ups unknown: the simulator's log could not be read, so it cannot be "
            "told whether the run depended on wall time"
        )
    over = f" (over {runs} runs)" if runs > 1 else ""
    return (
        f"the Eye fell behind the sim {give_ups} times{over}: the run depended on wall time; "
        "rerun on a quieter machine or raise --eye-sync-wait-s"
    )


def eye_sync_verdict(rep: dict[str, Any], runs: int = 1, say: Any = None) -> None:
    """Fails a mission's report (ok False, the message in error) when its eye_sync_give_ups
    says the sim gave the Eye up; says the message (say) too."""
    msg = eye_sync_failure(rep.get("eye_sync_give_ups"), runs)
    if msg is None:
        return
    rep["ok"] = False
    rep["eye_sync_error"] = msg
    rep["error"] = f"{rep['error']}; {msg}" if rep.get("error") else msg
    if say is not None:
        say(f"FAILED: {msg}")


def eye_lockstep_argv(latency_ms: float | None) -> list[object]:
    """autodrive-eye run's options for the lockstep of sim_argv (none when latency_ms is None)."""
    return [] if latency_ms is None else ["--sim-latency-ms", latency_ms]


def start(
    procs: ProcessGroup,
    eye: str,
    build: Path,
    map_name: str,
    folder: Path,
    url: str,
    cars: list[str],
    seed: int,
    fps: float,
    latency_ms: float | None,
) -> str:
    """Starts the pose source of --eye for cars (NIGEL1, ...; car i wears roof tag i) on the
    map's overhead cameras, logs and configs in folder, the Eye in lockstep with latency_ms
    [ms of sim time] unless None; returns what runs (for the report)."""
    if eye == "cameras":
        cams = eye_cameras.load(map_name)
        if not cams:
            raise RuntimeError(f"--eye cameras: map {map_name} has no eye_cameras (maps/)")
        tags = [(car, eye_cameras.sim_tag_id(i + 1)) for i, car in enumerate(cars)]
        (folder / "eye").mkdir(exist_ok=True)
        cfg = eye_cameras.write_eye_config(cams, folder / "eye", url, tags)
        argv: list[object] = [build / "bin" / "autodrive-eye", "run", "-c", cfg, "-q"]
        argv += eye_lockstep_argv(latency_ms)
        procs.start("autodrive-eye", argv, folder / "eye.log")
    elif eye == "standin":
        argv = [
            sys.executable,
            "-m",
            "autodrive.hil.city.eye_standin",
            "--vehicles",
            ",".join(cars),
        ]
        argv += ["--seed", seed, "--lcm-url", url, "--build", build]
        procs.start("eye-standin", argv, folder / "eye-standin.log")
    return describe(eye, map_name, fps, latency_ms)


def describe(eye: str, map_name: str, fps: float, latency_ms: float | None = None) -> str:
    """What --eye runs on the map (for the report)."""
    if eye == "cameras":
        n = len(eye_cameras.load(map_name)) or 1  # none listed: the map's one camera 'eye'
        what = f"autodrive-eye on {n} rendered overhead camera(s) at {fps:g} Hz of sim time"
        if latency_ms is None:
            return what + ", not in lockstep with the simulator"
        return what + f", in lockstep with the simulator: poses at capture + {latency_ms:g} ms"
    if eye == "standin":
        return "stand-in (test double): ground truth + the Eye's noise (city.eye_standin)"
    return "none: dead reckoning from the marked start pose"
