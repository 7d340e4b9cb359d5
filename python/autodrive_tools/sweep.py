"""Parking sweep: runs the HIL parking demo (autodrive_tools.demo, in this process) once per
seed, sequentially, each into OUT/seed<N>/, then aggregates the reports against the goals of
issue 7 and writes OUT/summary.json and OUT/parking_sweep.png. Progress on stderr; the last
stdout line is the summary as one JSON object. Does not build: run it through
`tools/bench parking`, which does.

A run counts as ok when the demo returned 0 and its report says ok (success and 0 collisions);
a run whose demo returns non-zero or leaves no report.json is a failure, and the sweep goes
on."""

from __future__ import annotations

import argparse
import json
import math
import os
import signal
import statistics
import sys
import time
import traceback
from pathlib import Path
from types import FrameType
from typing import Any

from . import demo, plots
from .geometry import to_world
from .mapfacts import parking_school
from .paths import OUT_DIR, RELEASE_BUILD
from .runfiles import read_columns

# The hil port range of docs/INTERFACES.md (tests take 7830/7832): a sweep does not hear a
# tools/demo that someone runs on the default port 7667 meanwhile, nor the HIL tests.
DEFAULT_LCM_URL = "udpm://239.255.76.67:7846?ttl=0"
# Goals of issue 7 (runtime/jetson/autonomy/README.md).
GOAL_RUNS = 10
GOAL_POS_ERROR_M = 0.02
GOAL_HEADING_ERROR_DEG = 2.0
GOAL_LOCALIZATION_RMS_M = 0.03
GOAL_WALL_S = 120.0
# Figures summarised by median and max over the runs that report them.
MEDIAN_MAX_KEYS = (
    "final_pos_error_m",
    "final_heading_error_deg",
    "localization_rms_m",
    "wall_s",
    "sim_s",
    "laser_odom_drift_pct",
    "ekf_odom_drift_pct",
)
PER_SEED_KEYS = MEDIAN_MAX_KEYS + ("min_clearance_m", "collisions", "path_length_m")
EXIT_FILE = "demo_exit_code"  # per seed dir: the demo's exit code, kept for --aggregate-only

Run = dict[str, Any]


def log(msg: str) -> None:
    print(msg, file=sys.stderr, flush=True)


def parse_args(argv: list[str]) -> argparse.Namespace:
    # Everything after --extra goes to the demo verbatim (it may start with "--").
    extra: list[str] = []
    if "--extra" in argv:
        i = argv.index("--extra")
        argv, extra = argv[:i], argv[i + 1 :]
        if not extra:
            sys.exit("parking_sweep: --extra needs at least one argument for the demo")
    slots = parking_school().slots
    p = argparse.ArgumentParser(
        prog="tools/bench parking",
        description="Run the HIL parking demo (tools/demo) over several seeds and aggregate "
        "success, final pose error [m, deg], localisation RMS [m], clearance [m] and wall time "
        "[s] against the goals of issue 7. Writes OUT/seed<N>/ (each run), OUT/summary.json and "
        "OUT/parking_sweep.png; prints the summary JSON as the last stdout line. Exit code 0 "
        "when the sweep ran (whether or not the goals are met), 2 bad input, 130 interrupted.",
        epilog="example: python -m autodrive_tools.sweep --seeds 2 --out /tmp/sweep "
        "--extra --realtime",
    )
    p.add_argument("--seeds", type=int, default=10, help="number of seeds to run (default 10)")
    p.add_argument("--first-seed", type=int, default=1, help="first seed (default 1)")
    p.add_argument(
        "--slot",
        type=int,
        default=None,
        help=f"parking slot 0..{slots - 1} (default: the demo's default)",
    )
    p.add_argument(
        "--out",
        default=str(OUT_DIR / "bench" / "parking"),
        help="output folder (default out/bench/parking)",
    )
    p.add_argument(
        "--build",
        default=os.environ.get("AUTODRIVE_BUILD", str(RELEASE_BUILD)),
        help="host build dir (default $AUTODRIVE_BUILD or build/release)",
    )
    p.add_argument(
        "--lcm-url",
        default=DEFAULT_LCM_URL,
        help=f"LCM URL for the runs (default {DEFAULT_LCM_URL})",
    )
    p.add_argument(
        "--run-timeout",
        type=float,
        default=600.0,
        help="stop a demo run after this many wall seconds [s] (default 600; the "
        "demo's own --timeout is 240 s of wall time)",
    )
    p.add_argument(
        "--aggregate-only",
        action="store_true",
        help="run nothing: aggregate the reports already in OUT/seed<N>/",
    )
    p.add_argument(
        "--extra",
        metavar="ARG",
        nargs="*",
        default=[],
        help="must come last: every following argument is passed to the demo "
        "(e.g. --extra --realtime)",
    )
    args = p.parse_args(argv)
    args.extra = extra
    if args.seeds < 1:
        p.error(f"--seeds {args.seeds}: need at least 1 seed")
    if args.slot is not None and not 0 <= args.slot < slots:
        p.error(f"--slot {args.slot}: Parking School has slots 0..{slots - 1}")
    if args.run_timeout <= 0:
        p.error(f"--run-timeout {args.run_timeout}: must be > 0 s")
    return args


def seed_dir(out: Path | str, seed: int) -> Path:
    return Path(out) / f"seed{seed}"


def on_stop_signal(signum: int, _frame: FrameType | None) -> None:
    # Between runs (a run handles its own signals): summarise what ran.
    raise KeyboardInterrupt(signal.Signals(signum).name)


def demo_argv(args: argparse.Namespace, seed: int) -> list[str]:
    argv = ["--build", str(args.build), "--out", str(seed_dir(args.out, seed))]
    argv += ["--seed", str(seed), "--headless", "--lcm-url", args.lcm_url]
    if args.slot is not None:
        argv += ["--slot", str(args.slot)]
    extra: list[str] = args.extra
    return argv + extra


def run_demo(args: argparse.Namespace, seed: int) -> int | None:
    """One demo run into OUT/seed<N>/; returns its exit code (None when it timed out)."""
    d = seed_dir(args.out, seed)
    d.mkdir(parents=True, exist_ok=True)
    for stale in ("report.json", "gt.csv", EXIT_FILE):  # a failed run must not reuse old figures
        (d / stale).unlink(missing_ok=True)
    deadline: float = time.monotonic() + args.run_timeout

    def timed_out() -> bool:
        return time.monotonic() > deadline

    code: int | None
    with open(d / "demo.log", "w") as console:  # the demo talks a lot: stdout is for the JSON
        try:
            code = demo.run(demo.parse_args(demo_argv(args, seed)), console, timed_out)
        except Exception:  # a crashed run is a failed run; the sweep goes on
            traceback.print_exc(file=console)
            code = 1
    if code == demo.EXIT_INTERRUPTED and timed_out():
        log(f"[parking] seed {seed}: still running after {args.run_timeout:.0f} s: stopped it")
        code = None
    (d / EXIT_FILE).write_text(f"{'timeout' if code is None else code}\n")
    return code


def load_run(out: Path, seed: int) -> Run:
    """The run of one seed as {seed, exit_code, report (dict or None), ok, error}."""
    d = seed_dir(out, seed)
    exit_code: int | str | None = None
    if (d / EXIT_FILE).exists():
        text = (d / EXIT_FILE).read_text().strip()
        exit_code = int(text) if text.lstrip("-").isdigit() else text
    report, error = None, None
    try:
        report = json.loads((d / "report.json").read_text())
        if not isinstance(report, dict):
            report, error = None, f"{d / 'report.json'}: not a JSON object"
    except FileNotFoundError:
        error = "no report.json"
    except (OSError, ValueError) as e:
        error = f"{d / 'report.json'}: unreadable ({e})"
    ok = bool(
        report
        and report.get("ok") is True
        and report.get("success") is True
        and report.get("collisions") == 0
        and exit_code in (0, None)
    )
    if report and not ok:  # the report's own reason first, then how the demo ended
        reasons = [report["error"]] if report.get("error") else []
        if report.get("collisions"):
            reasons.append(f"{report['collisions']} collision(s)")
        if report.get("success") is not True:
            reasons.append("not parked")
        if exit_code not in (0, None):
            reasons.append(f"demo exit {exit_code}")
        error = ", ".join(reasons) or "report not ok"
    elif error and exit_code not in (0, None):
        error += f", demo exit {exit_code}"
    return {"seed": seed, "exit_code": exit_code, "report": report, "ok": ok, "error": error}


def _number(report: dict[str, Any] | None, key: str) -> float | None:
    v = (report or {}).get(key)
    ok = isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
    return v if ok else None


def _all_within(values: list[float | None], bound: float) -> bool:
    return all(v is not None and v <= bound for v in values)


def _median_max(s: dict[str, Any], key: str, values: list[float | None]) -> None:
    vals = [v for v in values if v is not None]
    s[f"{key}_median"] = round(statistics.median(vals), 4) if vals else None
    s[f"{key}_max"] = round(max(vals), 4) if vals else None


def aggregate(runs: list[Run]) -> dict[str, Any]:
    """Summary figures of the runs (each from load_run), goals as booleans."""
    reps = [r["report"] for r in runs]
    per = {k: [_number(rep, k) for rep in reps] for k in PER_SEED_KEYS}
    s: dict[str, Any] = {
        "runs": len(runs),
        "successes": sum(r["ok"] for r in runs),
        "reports": sum(rep is not None for rep in reps),
        "collisions_total": sum(v for v in per["collisions"] if v is not None),
    }
    slots = {rep.get("slot") for rep in reps if rep and rep.get("slot") is not None}
    s["slot"] = slots.pop() if len(slots) == 1 else sorted(slots) or None
    for k in MEDIAN_MAX_KEYS:
        _median_max(s, k, per[k])
    # Laser odometry against its peer, the EKF's wheel/IMU odometry, over the same span.
    ratios = [
        a / b
        for a, b in zip(per["laser_odom_drift_pct"], per["ekf_odom_drift_pct"])
        if a is not None and b
    ]
    s["laser_over_ekf_drift_ratio_median"] = round(statistics.median(ratios), 3) if ratios else None
    clear = [v for v in per["min_clearance_m"] if v is not None]
    s["min_clearance_m_min"] = round(min(clear), 4) if clear else None
    # Goals of issue 7; each holds only if every run meets it (a run without a figure fails it).
    s["goal_all_success_no_collisions"] = s["successes"] == len(runs) and s["collisions_total"] == 0
    s["goal_final_pose"] = _all_within(per["final_pos_error_m"], GOAL_POS_ERROR_M) and _all_within(
        per["final_heading_error_deg"], GOAL_HEADING_ERROR_DEG
    )
    s["goal_localization_rms"] = _all_within(per["localization_rms_m"], GOAL_LOCALIZATION_RMS_M)
    s["goal_wall_s"] = _all_within(per["wall_s"], GOAL_WALL_S)
    s["goals_met"] = (
        len(runs) >= GOAL_RUNS
        and s["goal_all_success_no_collisions"]
        and s["goal_final_pose"]
        and s["goal_localization_rms"]
        and s["goal_wall_s"]
    )
    s["goal_bounds"] = {
        "runs": GOAL_RUNS,
        "final_pos_error_m": GOAL_POS_ERROR_M,
        "final_heading_error_deg": GOAL_HEADING_ERROR_DEG,
        "localization_rms_m": GOAL_LOCALIZATION_RMS_M,
        "wall_s": GOAL_WALL_S,
    }
    s["per_seed"] = {
        "seed": [r["seed"] for r in runs],
        "ok": [r["ok"] for r in runs],
        "exit_code": [r["exit_code"] for r in runs],
        "error": [r["error"] for r in runs],
        **per,
    }
    return s


def progress_line(i: int, n: int, run: Run, measured_wall_s: float | None) -> str:
    rep = run["report"] or {}
    parts = ["ok" if run["ok"] else f"FAILED ({run['error']})"]
    pos, head = _number(rep, "final_pos_error_m"), _number(rep, "final_heading_error_deg")
    if pos is not None:
        parts.append(f"{100 * pos:.1f} cm")
    if head is not None:
        parts.append(f"{head:.1f} deg")
    wall = _number(rep, "wall_s")
    wall = wall if wall is not None else measured_wall_s
    if wall is not None:
        parts.append(f"{wall:.1f} s wall")
    return f"[parking {i}/{n}] seed {run['seed']}: {', '.join(parts)}"


def _sweep_run(out: Path, run: Run) -> plots.SweepRun:
    """A run's ground truth in the world (gt.csv is in the run's start frame, and each seed
    starts elsewhere) and its goal, for the plot."""
    rep = run["report"] or {}
    st, g = rep.get("start_world"), rep.get("goal_world")
    if not (isinstance(st, list) and isinstance(g, list) and len(st) == 3 and len(g) == 3):
        return plots.SweepRun(run["seed"], run["ok"], None, None)
    try:
        gt = read_columns(seed_dir(out, run["seed"]) / "gt.csv", ["x_m", "y_m"])
    except (OSError, ValueError):
        return plots.SweepRun(run["seed"], run["ok"], None, None)
    world = [to_world(st, (x, y, 0.0)) for x, y in zip(gt["x_m"], gt["y_m"])]
    track = ([p[0] for p in world], [p[1] for p in world])
    return plots.SweepRun(run["seed"], run["ok"], track, (g[0], g[1]))


def plot(summary: dict[str, Any], runs: list[Run], out: Path, png: Path) -> None:
    per = summary["per_seed"]
    slot = summary["slot"] if summary["slot"] is not None else "?"
    plots.sweep(
        png,
        f"parking sweep: {summary['successes']}/{summary['runs']} parked without collision"
        f" (slot {slot}; red = failed)",
        per["seed"],
        per["ok"],
        per,
        (
            plots.SweepBar(
                "final_pos_error_m", 100.0, "final position error", "cm", 100 * GOAL_POS_ERROR_M
            ),
            plots.SweepBar(
                "final_heading_error_deg",
                1.0,
                "final heading error",
                "deg",
                GOAL_HEADING_ERROR_DEG,
            ),
            plots.SweepBar(
                "localization_rms_m", 100.0, "localisation RMS", "cm", 100 * GOAL_LOCALIZATION_RMS_M
            ),
        ),
        [_sweep_run(out, r) for r in runs],
    )


def write_json_atomic(path: Path, obj: Any) -> None:
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(json.dumps(obj, indent=2) + "\n")
    os.replace(tmp, path)


def run_seeds(args: argparse.Namespace, out: Path) -> tuple[list[Run], bool]:
    """Runs (or only loads) every seed; (runs, interrupted)."""
    seeds = list(range(args.first_seed, args.first_seed + args.seeds))
    runs: list[Run] = []
    for i, seed in enumerate(seeds, 1):
        measured = None
        if not args.aggregate_only:
            log(
                f"[parking {i}/{len(seeds)}] seed {seed}: running (log {seed_dir(out, seed)}/demo.log)"
            )
            t0 = time.monotonic()
            try:
                code = run_demo(args, seed)
            except KeyboardInterrupt:
                code = demo.EXIT_INTERRUPTED
            measured = time.monotonic() - t0
            if code == demo.EXIT_INTERRUPTED:
                log("[parking] interrupted: summarising the runs so far")
                return runs, True
        runs.append(load_run(out, seed))
        log(progress_line(i, len(seeds), runs[-1], measured))
    return runs, False


def main(argv: list[str] | None = None) -> int:
    args = parse_args(sys.argv[1:] if argv is None else argv)
    out = Path(args.out)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        log(f"[parking] ERROR: --out {out}: {e.strerror}")
        return 2
    if not args.aggregate_only:
        for prog in demo.PROGRAMS:
            if not (Path(args.build) / "bin" / prog).exists():
                log(
                    f"[parking] ERROR: --build {args.build}: bin/{prog} is missing "
                    "(tools/bench parking builds the release preset)"
                )
                return 2
        demo.parse_args(demo_argv(args, args.first_seed))  # a bad --extra fails here, once
    signal.signal(signal.SIGINT, on_stop_signal)
    signal.signal(signal.SIGTERM, on_stop_signal)
    runs, interrupted = run_seeds(args, out)
    if not runs:
        log("[parking] no run to summarise")
        return 130 if interrupted else 2
    summary = aggregate(runs)
    summary["lcm_url"] = args.lcm_url
    summary["extra_args"] = args.extra
    if interrupted:
        summary["interrupted"] = True
    write_json_atomic(out / "summary.json", summary)
    png = out / "parking_sweep.png"
    try:
        plot(summary, runs, out, png)
        log(f"[parking] wrote {out / 'summary.json'} and {png}")
    except Exception as e:  # the figures matter more than the picture
        log(f"[parking] plot failed ({type(e).__name__}: {e}); wrote {out / 'summary.json'}")
    log(
        f"[parking] {summary['successes']}/{summary['runs']} ok; final error median/max "
        f"{summary['final_pos_error_m_median']}/{summary['final_pos_error_m_max']} m, "
        f"{summary['final_heading_error_deg_median']}/{summary['final_heading_error_deg_max']} deg; "
        f"goals met: {summary['goals_met']}"
    )
    print(json.dumps(summary), flush=True)
    return 130 if interrupted else 0


if __name__ == "__main__":
    sys.exit(main())
