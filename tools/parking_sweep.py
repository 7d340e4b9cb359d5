#!/usr/bin/env python3
"""Parking sweep: runs the HIL parking demo (tools/demo.py) once per seed, sequentially, each
into OUT/seed<N>/, then aggregates the reports against the goals of issue 7 and writes
OUT/summary.json and OUT/parking_sweep.png. Progress on stderr; the last stdout line is the
summary as one JSON object. Does not build: run it through `tools/bench parking`, which does.

A run counts as ok when demo.py exited 0 and its report says ok (success and 0 collisions); a
run whose demo exits non-zero or leaves no report.json is a failure, and the sweep goes on."""
import argparse
import json
import math
import os
import pathlib
import signal
import statistics
import subprocess
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent
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
EXIT_FILE = "demo_exit_code"  # per seed dir: demo.py's exit code, kept for --aggregate-only


def log(msg):
    print(msg, file=sys.stderr, flush=True)


def parse_args(argv):
    # Everything after --extra goes to demo.py verbatim (it may start with "--").
    extra = []
    if "--extra" in argv:
        i = argv.index("--extra")
        argv, extra = argv[:i], argv[i + 1 :]
        if not extra:
            sys.exit("parking_sweep: --extra needs at least one argument for demo.py")
    p = argparse.ArgumentParser(
        prog="tools/parking_sweep.py",
        description="Run the HIL parking demo (tools/demo.py) over several seeds and aggregate "
        "success, final pose error [m, deg], localisation RMS [m], clearance [m] and wall time "
        "[s] against the goals of issue 7. Writes OUT/seed<N>/ (each run), OUT/summary.json and "
        "OUT/parking_sweep.png; prints the summary JSON as the last stdout line. Exit code 0 "
        "when the sweep ran (whether or not the goals are met), 2 bad input, 130 interrupted.",
        epilog="example: tools/parking_sweep.py --seeds 2 --out /tmp/sweep --extra --realtime",
    )
    p.add_argument("--seeds", type=int, default=10, help="number of seeds to run (default 10)")
    p.add_argument("--first-seed", type=int, default=1, help="first seed (default 1)")
    p.add_argument(
        "--slot", type=int, default=None, help="parking slot 0..5 (default: the demo's default)"
    )
    p.add_argument(
        "--out",
        default=str(ROOT / "out" / "bench" / "parking"),
        help="output folder (default out/bench/parking)",
    )
    p.add_argument(
        "--build",
        default=os.environ.get("AUTODRIVE_BUILD", str(ROOT / "build" / "release")),
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
        help="must come last: every following argument is passed to demo.py "
        "(e.g. --extra --realtime)",
    )
    args = p.parse_args(argv)
    args.extra = extra
    if args.seeds < 1:
        p.error(f"--seeds {args.seeds}: need at least 1 seed")
    if args.slot is not None and not 0 <= args.slot <= 5:
        p.error(f"--slot {args.slot}: Parking School has slots 0..5")
    if args.run_timeout <= 0:
        p.error(f"--run-timeout {args.run_timeout}: must be > 0 s")
    return args


def seed_dir(out, seed):
    return pathlib.Path(out) / f"seed{seed}"


def stop_demo(proc):
    """SIGINT (demo.py then stops its children and writes its report), SIGKILL after 30 s."""
    if proc.poll() is None:
        proc.send_signal(signal.SIGINT)
    try:
        proc.wait(timeout=30)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()


def on_stop_signal(signum, _frame):
    # Also when SIGINT was ignored at start (a background job) and for a SIGTERM sent to the
    # sweep alone: stop the running demo, then summarise what ran.
    raise KeyboardInterrupt(signal.Signals(signum).name)


def run_demo(args, seed):
    """One demo.py run into OUT/seed<N>/; returns its exit code (None when it timed out)."""
    d = seed_dir(args.out, seed)
    d.mkdir(parents=True, exist_ok=True)
    for stale in ("report.json", "gt.csv", EXIT_FILE):  # a failed run must not reuse old figures
        (d / stale).unlink(missing_ok=True)
    argv = [
        sys.executable,
        str(ROOT / "tools" / "demo.py"),
        "--build",
        str(args.build),
        "--out",
        str(d),
        "--seed",
        str(seed),
        "--headless",
        "--lcm-url",
        args.lcm_url,
    ]
    if args.slot is not None:
        argv += ["--slot", str(args.slot)]
    argv += args.extra
    with open(d / "demo.log", "w") as logf:  # demo.py talks on stdout: keep ours for the JSON
        proc = subprocess.Popen(argv, stdout=logf, stderr=subprocess.STDOUT, cwd=ROOT)
        try:
            code = proc.wait(timeout=args.run_timeout)
        except subprocess.TimeoutExpired:
            log(f"[parking] seed {seed}: still running after {args.run_timeout:.0f} s: stopping it")
            stop_demo(proc)
            code = None
        except KeyboardInterrupt:
            stop_demo(proc)
            raise
    (d / EXIT_FILE).write_text(f"{'timeout' if code is None else code}\n")
    return code


def load_run(out, seed):
    """The run of one seed as {seed, exit_code, report (dict or None), ok, error}."""
    d = seed_dir(out, seed)
    exit_code = None
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


def _number(report, key):
    v = (report or {}).get(key)
    return (
        v if isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) else None
    )


def _all_within(values, bound):
    return all(v is not None and v <= bound for v in values)


def aggregate(runs):
    """Summary figures of the runs (each from load_run), goals as booleans."""
    reps = [r["report"] for r in runs]
    per = {k: [_number(rep, k) for rep in reps] for k in PER_SEED_KEYS}
    s = {
        "runs": len(runs),
        "successes": sum(r["ok"] for r in runs),
        "reports": sum(rep is not None for rep in reps),
        "collisions_total": sum(v for v in per["collisions"] if v is not None),
    }
    slots = {rep.get("slot") for rep in reps if rep and rep.get("slot") is not None}
    s["slot"] = slots.pop() if len(slots) == 1 else sorted(slots) or None
    for k in MEDIAN_MAX_KEYS:
        vals = [v for v in per[k] if v is not None]
        s[f"{k}_median"] = round(statistics.median(vals), 4) if vals else None
        s[f"{k}_max"] = round(max(vals), 4) if vals else None
    # Laser odometry against its peer, the EKF's wheel/IMU odometry, over the same span of each run.
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


def progress_line(i, n, run, measured_wall_s):
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


def _read_gt(path):
    xs, ys = [], []
    try:
        with open(path) as f:
            header = f.readline().strip().split(",")
            ix, iy = header.index("x_m"), header.index("y_m")
            for line in f:
                cols = line.split(",")
                xs.append(float(cols[ix]))
                ys.append(float(cols[iy]))
    except (OSError, ValueError, IndexError):
        return None
    return xs, ys


def _start_and_goal(rep):
    """The run's world start and goal poses [m, m, rad], or None."""
    st, g = (rep or {}).get("start_world"), (rep or {}).get("goal_world")
    if isinstance(st, list) and isinstance(g, list) and len(st) == 3 and len(g) == 3:
        return st, g
    return None


def _to_world(start, xs, ys):
    """gt.csv is in the run's start frame: each seed starts elsewhere, so plot in the world."""
    c, s = math.cos(start[2]), math.sin(start[2])
    return (
        [start[0] + c * x - s * y for x, y in zip(xs, ys)],
        [start[1] + s * x + c * y for x, y in zip(xs, ys)],
    )


def plot(summary, runs, out, png):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    per = summary["per_seed"]
    seeds = per["seed"]
    x = list(range(len(seeds)))
    colours = ["tab:blue" if ok else "tab:red" for ok in per["ok"]]
    fig, axs = plt.subplots(2, 2, figsize=(12, 9))
    bars = (
        (
            axs[0][0],
            "final_pos_error_m",
            100.0,
            "final position error",
            "cm",
            100 * GOAL_POS_ERROR_M,
        ),
        (
            axs[0][1],
            "final_heading_error_deg",
            1.0,
            "final heading error",
            "deg",
            GOAL_HEADING_ERROR_DEG,
        ),
        (
            axs[1][0],
            "localization_rms_m",
            100.0,
            "localisation RMS",
            "cm",
            100 * GOAL_LOCALIZATION_RMS_M,
        ),
    )
    for ax, key, scale, label, unit, goal in bars:
        vals = [scale * v if v is not None else 0.0 for v in per[key]]
        ax.bar(x, vals, color=colours)
        for xi, v in zip(x, per[key]):
            if v is None:
                ax.text(xi, 0, "no data", rotation=90, ha="center", va="bottom", fontsize=8)
        ax.axhline(goal, color="tab:green", ls="--", lw=1.2, label=f"goal <= {goal:g} {unit}")
        ax.set_xticks(x, [str(s) for s in seeds])
        ax.set_xlabel("seed")
        ax.set_ylabel(f"{label} [{unit}]")
        ax.legend(loc="upper right", fontsize=8)
    ax = axs[1][1]
    goals = set()
    for r in runs:
        gt = _read_gt(seed_dir(out, r["seed"]) / "gt.csv")
        sg = _start_and_goal(r["report"])
        if gt and sg:
            ax.plot(
                *_to_world(sg[0], *gt),
                "-",
                lw=1,
                color=None if r["ok"] else "tab:red",
                label=f"seed {r['seed']}" + ("" if r["ok"] else " (failed)"),
            )
            goals.add(tuple(round(v, 4) for v in sg[1][:2]))
    for i, g in enumerate(sorted(goals)):
        ax.plot([g[0]], [g[1]], "kx", ms=10, label="goal (rear axle)" if i == 0 else None)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m] (world)")
    ax.set_ylabel("y [m] (world)")
    ax.set_title("ground-truth trajectories")
    if ax.lines:
        ax.legend(loc="best", fontsize=7)
    fig.suptitle(
        f"parking sweep: {summary['successes']}/{summary['runs']} parked without collision"
        f" (slot {summary['slot'] if summary['slot'] is not None else '?'}; red = failed)"
    )
    fig.tight_layout()
    tmp = png.with_name(png.name + ".tmp")
    fig.savefig(tmp, dpi=110, format="png")
    plt.close(fig)
    os.replace(tmp, png)


def write_json_atomic(path, obj):
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(json.dumps(obj, indent=2) + "\n")
    os.replace(tmp, path)


def main(argv):
    args = parse_args(argv)
    out = pathlib.Path(args.out)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        log(f"[parking] ERROR: --out {out}: {e.strerror}")
        return 2
    if not args.aggregate_only:
        for prog in ("autodrive-sim", "autodrive-runtime", "autodrive-autonomy"):
            if not (pathlib.Path(args.build) / "bin" / prog).exists():
                log(
                    f"[parking] ERROR: --build {args.build}: bin/{prog} is missing "
                    "(tools/bench parking builds the release preset)"
                )
                return 2
    signal.signal(signal.SIGINT, on_stop_signal)
    signal.signal(signal.SIGTERM, on_stop_signal)
    seeds = list(range(args.first_seed, args.first_seed + args.seeds))
    runs, interrupted = [], False
    for i, seed in enumerate(seeds, 1):
        if not args.aggregate_only:
            log(
                f"[parking {i}/{len(seeds)}] seed {seed}: running (log {seed_dir(out, seed)}/demo.log)"
            )
            t0 = time.monotonic()
            try:
                run_demo(args, seed)
            except KeyboardInterrupt:
                log("[parking] interrupted: summarising the runs so far")
                interrupted = True
                break
            measured = time.monotonic() - t0
        else:
            measured = None
        runs.append(load_run(out, seed))
        log(progress_line(i, len(seeds), runs[-1], measured))
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
    sys.exit(main(sys.argv[1:]))
