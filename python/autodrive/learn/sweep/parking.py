"""Parking sweep: runs the HIL parking demo (autodrive.hil.demo) once per seed (and slot), as
independent jobs on Ray (autodrive.learn.sweep.jobs: embedded and local by default, --address
joins a cluster, --serial runs them one after the other in this process), each on its own LCM
port and in its own temp dir on the node that runs it; the job sends its files back and they
land in OUT/seed<N>/ (OUT/slot<K>/seed<N>/ for several slots). Then it aggregates the reports
against the goals of issue 7 and writes OUT/summary.json and OUT/parking_sweep.png. Progress on
stderr; the last stdout line is the summary as one JSON object. Does not build: run it through
`tools/sweep parking` or `tools/bench parking`, which do.

A run counts as ok when the demo returned 0 and its report says ok (success and 0 collisions);
a run whose demo returns non-zero or leaves no report.json is a failure, and the sweep goes
on."""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import shutil
import signal
import statistics
import sys
import tempfile
import time
import traceback
from dataclasses import dataclass
from pathlib import Path
from types import FrameType
from typing import Any

from autodrive.bench.goals import at_least, equals, judge
from autodrive.core import seeds
from autodrive.hil import demo
from autodrive.core import plots
from autodrive.learn.sweep import jobs as sweep_ray
from autodrive.core.geometry import to_world
from autodrive.maps.facts import parking_school
from autodrive.hil.missions import EXIT_INTERRUPTED
from autodrive.core.settings import OUT_DIR, RELEASE_BUILD
from autodrive.core.runfiles import read_columns

# The hil port range of docs/INTERFACES.md (tests take 7830/7832): a sweep does not hear a
# tools/demo that someone runs on the default port 7667 meanwhile, nor the HIL tests. Job i of
# a sweep takes this port + i, so jobs running at the same time on one machine never cross.
DEFAULT_LCM_URL = "udpm://239.255.76.67:7846?ttl=0"
# The files a job sends back (the LCM log and its MCAP only with --keep-logs: megabytes).
BULKY_FILES = ("run.lcmlog", "run.mcap")
# The parking goals (docs/results/parking.md).
GOAL_RUNS = 10
GOAL_POS_ERROR_M = 0.02
GOAL_HEADING_ERROR_DEG = 2.0
GOAL_LOCALIZATION_RMS_M = 0.03
GOAL_WALL_S = 120.0
# Issue 7's goals, through the benches' one rule (autodrive.bench.goals): each per-run goal holds
# only if every run meets it, and fewer than GOAL_RUNS runs cannot meet them.
GOALS = {
    "runs": at_least("runs", GOAL_RUNS),
    "all_success_no_collisions": equals("goal_all_success_no_collisions", True),
    "final_pose": equals("goal_final_pose", True),
    "localization_rms": equals("goal_localization_rms", True),
    "wall_s": equals("goal_wall_s", True),
}
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
# Per-seed facts that the seed and slot fix (the scenario), kept as they are.
PER_SEED_FACTS = ("start_world", "goal_world")
# Two sweeps of the same seeds agree when the scenario and each run's success are the same
# and the closed-loop figures are within these. Not exact: in the demo's --lockstep-client the
# runtime's and the autonomy's commands land at sim steps that depend on wall-clock scheduling
# (docs/design/clocks.md), so two runs of one seed on one machine differ this much too.
AGREE_TOLERANCE = {
    "final_pos_error_m": 0.01,
    "final_heading_error_deg": 2.0,
    "localization_rms_m": 0.01,
}
EXIT_FILE = "demo_exit_code"  # per seed dir: the demo's exit code, kept for --aggregate-only

Run = dict[str, Any]


def log(msg: str) -> None:
    print(msg, file=sys.stderr, flush=True)


def parse_args(argv: list[str], prog: str = "tools/sweep parking") -> argparse.Namespace:
    # Everything after --extra goes to the demo verbatim (it may start with "--").
    extra: list[str] = []
    if "--extra" in argv:
        i = argv.index("--extra")
        argv, extra = argv[:i], argv[i + 1 :]
        if not extra:
            sys.exit("parking_sweep: --extra needs at least one argument for the demo")
    slots = parking_school().slots
    p = argparse.ArgumentParser(
        prog=prog,
        description="Run the HIL parking demo (tools/demo) over several seeds (and slots) as "
        "independent jobs on Ray, and aggregate success, final pose error [m, deg], "
        "localisation RMS [m], clearance [m] and wall time [s] against the goals of issue 7. "
        "Writes OUT/seed<N>/ (each run; OUT/slot<K>/seed<N>/ with several slots), "
        "OUT/summary.json and OUT/parking_sweep.png; prints the summary JSON as the last stdout "
        "line. Exit code 0 when the sweep ran (whether or not the goals are met), 2 bad input, "
        "130 interrupted.",
        epilog="examples: tools/sweep parking --seeds 4 --workers 2; tools/sweep parking "
        "--seeds 20 --address 192.168.1.10:6379 (a Ray cluster of lab machines: docs/guides/sweeps.md, "
        "'Sweeps on Ray'); tools/sweep parking --seeds 2 --serial --extra --realtime",
    )
    p.add_argument("--seeds", type=int, default=10, help="number of seeds to run (default 10)")
    p.add_argument(
        "--first-seed",
        type=int,
        default=seeds.DEVELOPMENT_MISSION_SEED,
        help=f"first seed (default {seeds.DEVELOPMENT_MISSION_SEED}, a development seed: "
        "autodrive.core.seeds; tools/bench parking runs evaluation seeds)",
    )
    p.add_argument(
        "--slot",
        type=int,
        default=None,
        help=f"parking slot 0..{slots - 1} (default: the demo's default)",
    )
    p.add_argument(
        "--slots",
        default=None,
        metavar="K[,K...]",
        help="several parking slots: every seed runs at each (OUT/slot<K>/seed<N>/)",
    )
    p.add_argument(
        "--out",
        default=str(OUT_DIR / "sweep" / "parking"),
        help="output folder (default out/sweep/parking)",
    )
    p.add_argument(
        "--build",
        default=os.environ.get("AUTODRIVE_BUILD", str(RELEASE_BUILD)),
        help="host build dir, the same path on every node (default $AUTODRIVE_BUILD or "
        "build/release)",
    )
    p.add_argument(
        "--lcm-url",
        default=DEFAULT_LCM_URL,
        help=f"LCM URL of the first job; job i takes its port + i (default {DEFAULT_LCM_URL})",
    )
    p.add_argument(
        "--workers",
        type=int,
        default=1,
        help="local Ray: jobs at the same time (default 1: one parking run keeps about two "
        "cores busy); ignored with --address (the cluster's CPUs decide)",
    )
    p.add_argument(
        "--address",
        default=None,
        metavar="HOST:PORT",
        help="join this Ray cluster (from `ray start --head`) instead of starting a local one",
    )
    p.add_argument(
        "--serial",
        action="store_true",
        help="no Ray: run the jobs one after the other in this process (the reference)",
    )
    p.add_argument(
        "--keep-logs",
        action="store_true",
        help="also bring back each run's run.lcmlog and run.mcap (megabytes each)",
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
        help="run nothing: aggregate the reports already in OUT/",
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
    args.slot_list = [args.slot]
    if args.slots is not None:
        if args.slot is not None:
            p.error("--slot and --slots: choose one")
        try:
            args.slot_list = [int(k) for k in args.slots.split(",")]
        except ValueError:
            p.error(f"--slots {args.slots}: want slot numbers separated by commas, e.g. 0,2,5")
        bad = [k for k in args.slot_list if not 0 <= k < slots]
        if bad or len(set(args.slot_list)) != len(args.slot_list):
            p.error(f"--slots {args.slots}: want distinct slots of 0..{slots - 1}")
    if args.run_timeout <= 0:
        p.error(f"--run-timeout {args.run_timeout}: must be > 0 s")
    if args.workers < 1:
        p.error(f"--workers {args.workers}: need at least 1 worker")
    if args.serial and args.address:
        p.error(f"--address {args.address} and --serial: choose one")
    try:
        job_lcm_url(args.lcm_url, 0)
    except ValueError as e:
        p.error(str(e))
    return args


@dataclass(frozen=True)
class Job:
    """One demo run of a sweep: its seed, slot (None: the demo's default) and place."""

    index: int
    seed: int
    slot: int | None
    multi_slot: bool

    def dir(self, out: Path | str) -> Path:
        if self.multi_slot:
            return Path(out) / f"slot{self.slot}" / f"seed{self.seed}"
        return seed_dir(out, self.seed)

    def name(self) -> str:
        return f"slot {self.slot} seed {self.seed}" if self.multi_slot else f"seed {self.seed}"


def jobs_of(args: argparse.Namespace) -> list[Job]:
    """Every (slot, seed) of the options, slot-major, numbered."""
    slots: list[int | None] = args.slot_list
    pairs = [(k, s) for k in slots for s in range(args.first_seed, args.first_seed + args.seeds)]
    return [Job(i, s, k, len(slots) > 1) for i, (k, s) in enumerate(pairs)]


def seed_dir(out: Path | str, seed: int) -> Path:
    return Path(out) / f"seed{seed}"


def job_lcm_url(base: str, index: int) -> str:
    """The base URL with its port + index; ValueError naming the URL when it has no port."""
    m = re.fullmatch(r"(udpm://[0-9.]+:)([0-9]+)(\?.*)?", base)
    if not m:
        raise ValueError(
            f"--lcm-url {base}: want udpm://GROUP:PORT[?opts] (each job takes PORT + i)"
        )
    port = int(m.group(2)) + index
    if not 1024 <= port <= 65535:
        raise ValueError(f"--lcm-url {base}: port {port} of job {index} is outside 1024..65535")
    return f"{m.group(1)}{port}{m.group(3) or ''}"


def on_stop_signal(signum: int, _frame: FrameType | None) -> None:
    # Between runs (a run handles its own signals): summarise what ran.
    raise KeyboardInterrupt(signal.Signals(signum).name)


@dataclass(frozen=True)
class JobSpec:
    """What a node needs to run one job (picklable: it travels to Ray workers)."""

    seed: int
    slot: int | None
    build: str
    lcm_url: str
    extra: tuple[str, ...]
    run_timeout_s: float
    keep_logs: bool


def spec_of(args: argparse.Namespace, job: Job) -> JobSpec:
    return JobSpec(
        job.seed,
        job.slot,
        str(args.build),
        job_lcm_url(args.lcm_url, job.index),
        tuple(args.extra),
        float(args.run_timeout),
        bool(args.keep_logs),
    )


def demo_argv(spec: JobSpec, out: Path) -> list[str]:
    argv = ["--build", spec.build, "--out", str(out)]
    argv += ["--seed", str(spec.seed), "--headless", "--lcm-url", spec.lcm_url]
    if spec.slot is not None:
        argv += ["--slot", str(spec.slot)]
    return argv + list(spec.extra)


JobResult = dict[str, Any]


def run_job(spec: JobSpec) -> JobResult:
    """One demo run, on whichever node runs it, in a temp dir of that node: {exit_code (None
    when it timed out), files: {name: bytes}} (the run's files, to land in the job's dir)."""
    tmp = Path(tempfile.mkdtemp(prefix=f"autodrive-sweep-seed{spec.seed}-"))
    deadline: float = time.monotonic() + spec.run_timeout_s

    def timed_out() -> bool:
        return time.monotonic() > deadline

    code: int | None
    try:
        with open(tmp / "demo.log", "w") as console:  # the demo talks a lot: stdout is for JSON
            try:
                code = demo.run(demo.parse_args(demo_argv(spec, tmp)), console, timed_out)
            except KeyboardInterrupt:  # a cancelled Ray job
                code = EXIT_INTERRUPTED
            except Exception:  # a crashed run is a failed run; the sweep goes on
                traceback.print_exc(file=console)
                code = 1
            if code == EXIT_INTERRUPTED and timed_out():
                print(
                    f"[sweep] still running after {spec.run_timeout_s:.0f} s: stopped", file=console
                )
                code = None
        files = {
            f.name: f.read_bytes()
            for f in sorted(tmp.iterdir())
            if f.is_file() and (spec.keep_logs or f.name not in BULKY_FILES)
        }
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return {"exit_code": code, "files": files}


def store_job(out: Path, job: Job, result: JobResult) -> None:
    """A job's files into its dir, replacing what an earlier sweep left there."""
    d = job.dir(out)
    if d.exists():
        shutil.rmtree(d)
    d.mkdir(parents=True)
    for name, data in result["files"].items():
        (d / Path(name).name).write_bytes(data)
    code = result["exit_code"]
    (d / EXIT_FILE).write_text(f"{'timeout' if code is None else code}\n")


def load_run(out: Path, job: Job) -> Run:
    """The run of one job as {seed, slot, exit_code, report (dict or None), ok, error}."""
    d = job.dir(out)
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
    run = {"seed": job.seed, "exit_code": exit_code, "report": report, "ok": ok, "error": error}
    run["slot"] = job.slot
    run["dir"] = str(d)
    return run


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
    run_seeds = [r["seed"] for r in runs]
    span = (
        seeds.span(min(run_seeds), max(run_seeds) - min(run_seeds) + 1)
        if run_seeds
        else seeds.unseeded("no runs")
    )
    judge(s, GOALS, span)
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
    if any(r.get("slot") is not None for r in runs):
        s["per_seed"]["slot"] = [r.get("slot") for r in runs]
    for k in PER_SEED_FACTS:
        s["per_seed"][k] = [(rep or {}).get(k) for rep in reps]
    return s


def disagreements(a: dict[str, Any], b: dict[str, Any]) -> list[str]:
    """How two sweep summaries of the same seeds differ beyond AGREE_TOLERANCE ([] = they
    agree): seeds, slots, per-seed success and scenario exactly, figures within tolerance."""
    pa, pb = a["per_seed"], b["per_seed"]
    exact = ("seed", "slot", "ok") + PER_SEED_FACTS
    out = [f"{k}: {pa.get(k)} != {pb.get(k)}" for k in exact if pa.get(k) != pb.get(k)]
    if out:
        return out
    for k, tol in AGREE_TOLERANCE.items():
        for seed, x, y in zip(pa["seed"], pa[k], pb[k]):
            if (x is None) != (y is None) or (x is not None and abs(x - y) > tol):
                out.append(f"seed {seed} {k}: {x} vs {y} (tolerance {tol})")
    return out


def progress_line(i: int, n: int, name: str, run: Run, measured_wall_s: float | None) -> str:
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
    return f"[parking {i}/{n}] {name}: {', '.join(parts)}"


def _sweep_run(run: Run) -> plots.SweepRun:
    """A run's ground truth in the world (gt.csv is in the run's start frame, and each seed
    starts elsewhere) and its goal, for the plot."""
    rep = run["report"] or {}
    st, g = rep.get("start_world"), rep.get("goal_world")
    if not (isinstance(st, list) and isinstance(g, list) and len(st) == 3 and len(g) == 3):
        return plots.SweepRun(run["seed"], run["ok"], None, None)
    try:
        gt = read_columns(Path(run["dir"]) / "gt.csv", ["x_m", "y_m"])
    except (OSError, ValueError):
        return plots.SweepRun(run["seed"], run["ok"], None, None)
    world = [to_world(st, (x, y, 0.0)) for x, y in zip(gt["x_m"], gt["y_m"])]
    track = ([p[0] for p in world], [p[1] for p in world])
    return plots.SweepRun(run["seed"], run["ok"], track, (g[0], g[1]))


def plot(summary: dict[str, Any], runs: list[Run], png: Path) -> None:
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
        [_sweep_run(r) for r in runs],
    )


def write_json_atomic(path: Path, obj: Any) -> None:
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(json.dumps(obj, indent=2) + "\n")
    os.replace(tmp, path)


def run_jobs(
    args: argparse.Namespace, out: Path, jobs: list[Job]
) -> tuple[list[Run], bool, dict[str, Any]]:
    """Runs (or only loads) every job; (runs in job order, interrupted, facts of the pool)."""
    if args.aggregate_only:
        runs = [load_run(out, job) for job in jobs]
        for i, (job, run) in enumerate(zip(jobs, runs), 1):
            log(progress_line(i, len(jobs), job.name(), run, None))
        return runs, False, {}
    try:
        pool = sweep_ray.open_pool(args.workers, args.address, args.serial)
    except (ValueError, RuntimeError) as e:
        raise SystemExit(f"[parking] ERROR: {e}") from None
    log(f"[parking] {len(jobs)} job(s) {pool.describe()}; ready in {pool.init_s:.1f} s")
    hosts: dict[int, str] = {}
    finished = 0

    def done(i: int, result: JobResult, host: str, wall_s: float) -> None:
        nonlocal finished
        finished += 1
        hosts[i] = host
        store_job(out, jobs[i], result)
        run = load_run(out, jobs[i])
        log(progress_line(finished, len(jobs), f"{jobs[i].name()} on {host}", run, wall_s))
        if result["exit_code"] == EXIT_INTERRUPTED:  # Ctrl-C during a serial run
            raise KeyboardInterrupt

    for job in jobs:  # a failed run must not leave old figures behind
        if job.dir(out).exists():
            shutil.rmtree(job.dir(out))
    specs = [spec_of(args, job) for job in jobs]
    t0 = time.monotonic()
    interrupted = False
    try:
        sweep_ray.run_jobs(pool, run_job, specs, done)
    except KeyboardInterrupt:
        interrupted = True
        log("[parking] interrupted: summarising the runs that finished")
    finally:
        sweep_s = time.monotonic() - t0
        sweep_ray.close_pool(pool)
    facts: dict[str, Any] = {
        "pool": pool.describe(),
        "workers": None if pool.address else (1 if pool.serial else pool.workers),
        "address": pool.address,
        "ray_init_s": round(pool.init_s, 2),
        "sweep_wall_s": round(sweep_s, 2),
    }
    finished_jobs = [job for job in jobs if job.index in hosts]
    runs = [load_run(out, job) for job in finished_jobs]
    for run, job in zip(runs, finished_jobs):
        run["host"] = hosts[job.index]
    return runs, interrupted, facts


def main(argv: list[str] | None = None, prog: str = "tools/sweep parking") -> int:
    args = parse_args(sys.argv[1:] if argv is None else argv, prog)
    out = Path(args.out)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        log(f"[parking] ERROR: --out {out}: {e.strerror}")
        return 2
    jobs = jobs_of(args)
    if not args.aggregate_only:
        for p in demo.PROGRAMS:
            if not (Path(args.build) / "bin" / p).exists():
                log(
                    f"[parking] ERROR: --build {args.build}: bin/{p} is missing "
                    "(tools/sweep and tools/bench build the release preset)"
                )
                return 2
        demo.parse_args(demo_argv(spec_of(args, jobs[0]), out))  # a bad --extra fails here
    signal.signal(signal.SIGINT, on_stop_signal)
    signal.signal(signal.SIGTERM, on_stop_signal)
    runs, interrupted, facts = run_jobs(args, out, jobs)
    if not runs:
        log("[parking] no run to summarise")
        return 130 if interrupted else 2
    summary = aggregate(runs)
    if "host" in runs[0]:
        summary["per_seed"]["host"] = [r.get("host") for r in runs]
    summary.update(facts)
    summary["lcm_url"] = args.lcm_url
    summary["extra_args"] = args.extra
    if interrupted:
        summary["interrupted"] = True
    write_json_atomic(out / "summary.json", summary)
    png = out / "parking_sweep.png"
    try:
        plot(summary, runs, png)
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
