"""HIL demo orchestration: starts the simulator (Parking School), the unchanged Jetson runtime
on the simulator's ptys, the car's pose source (--eye: by default autodrive-eye on the rendered
overhead camera), a mission (parking or loop) and lcm-logger; stops everything cleanly (also on
Ctrl-C); then writes OUT: report.json, PNG plots and the LCM log of the run.

CLI: tools/demo --help (python -m autodrive.hil.demo). In-process: run(parse_args(argv))."""

from __future__ import annotations

import argparse
import json
import math
import os
import shutil
import signal
import sys
import time
from collections.abc import Callable
from pathlib import Path
from types import FrameType
from typing import Any, TextIO

import yaml

from autodrive.core import channels, command_auth, lcmtypes, seeds
from autodrive.hil import pose_source, report
from autodrive.devtools.inspect import export_mcap
from autodrive.hil.missions import (
    EXIT_INTERRUPTED,
    PTY_TIMEOUT_S,
    MissionContext,
    instance_lcm_url,
    record_children,
    loop,
    parking,
    smart_city,
)
from autodrive.core.settings import EYE_SIM_CONFIG, OUT_DIR, RELEASE_BUILD, RUNTIME_HIL_CONFIG
from autodrive.core.proc import ProcessGroup, wait_for_path

VEHICLE = channels.vehicle_name(1)
MAP = "parking_school"
PROGRAMS = ("autodrive-sim", "autodrive-runtime", "autodrive-autonomy")
# The default scenario's unmapped box (x, y [m], T [s], half sizes [m], R [m]), on the direct
# way from the spawn to slot 2. After a mapping route it steps out once the car comes back
# within 0.5 m of it, and not before 8 s of sim time: the car starts within 0.5 m of it, and a
# slow start of the route (a loaded machine, ASan) must not let the mapping see it; mapping
# standing still, it appears at 3.5 s, after the map is saved.
DEFAULT_LATE_BOX = "-0.62,0.76,8,0.06,0.06,0.5"
DEFAULT_LATE_BOX_STILL = "-0.62,0.76,3.5"
DEFAULT_MAPPING_ROUTE = "-0.35,0,0"
# The simulator's own time limit [s of sim time], a backstop behind the demo's.
LOOP_SIM_MARGIN_S = 8.0
PARKING_SIM_MARGIN_S = 30.0
PARKING_LOCKSTEP_RTF_BOUND = 20.0  # the fastest a lockstep run is assumed to go
PARKING_TIMEOUT_S = 240.0  # the default --timeout of parking and loop [s wall]


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    p = argparse.ArgumentParser(
        prog="tools/demo",
        description="Run the Nigel HIL demo: autodrive-sim (Parking School) + the unchanged "
        "autodrive-runtime on its ptys + a driver, recorded with lcm-logger. Writes "
        "out/demo/{report.json,*.png,run.lcmlog,run.mcap}.",
    )
    p.add_argument("--build", default=str(RELEASE_BUILD), help="host build dir")
    p.add_argument("--out", default=str(OUT_DIR / "demo"), help="output folder")
    p.add_argument(
        "--seed",
        type=int,
        default=seeds.DEVELOPMENT_MISSION_SEED,
        help="scenario seed: sensor noise, IMU biases, AMCL, and the start pose (see --start); "
        f"default {seeds.DEVELOPMENT_MISSION_SEED}, a development seed (autodrive.core.seeds)",
    )
    p.add_argument(
        "--mission",
        choices=("parking", "loop", "smart-city", "cloning", "intersection"),
        default="parking",
        help="parking (default): map, localise, plan and park autonomously; loop: "
        "drive a stadium track with pure pursuit on the EKF; smart-city: three cars in Tiny Town "
        "under the Smart City Manager; cloning: Driving School from the camera with a "
        "behavioural-cloning model (its own options: --mission cloning --help); intersection: "
        "four cars cross Intersection School with autodrive-marl (its own options: --mission "
        "intersection --help)",
    )
    p.add_argument("--slot", type=int, default=2, help="parking: target slot 0..5")
    p.add_argument(
        "--start",
        metavar="X,Y,YAW_DEG",
        help="parking: the car's start pose in the world [m, m, deg] (default: the "
        "map's spawn moved by up to 5 cm and 5 deg, drawn from --seed; seed 0: exactly "
        "the spawn)",
    )
    p.add_argument(
        "--late-box",
        metavar="X,Y,T[,SX,SY[,R]]",
        action="append",
        default=[],
        help="parking: a box the map does not have appears at world (X, Y) [m] at sim "
        "time T [s] (half sizes SX, SY [m]; with R, once the car is within R [m]); "
        "repeatable; replaces the default box. Write --late-box=-0.6,... for negative "
        f"X. Default: {DEFAULT_LATE_BOX} ({DEFAULT_LATE_BOX_STILL} with an empty "
        "--mapping-route): on the direct way to slot 2, after mapping; the car must "
        "see it and replan around it",
    )
    p.add_argument(
        "--mapping-route",
        metavar="X,Y,YAW_DEG[;...]",
        default=DEFAULT_MAPPING_ROUTE,
        help="parking: after mapping standing still, the car drives these poses of "
        "its start frame [m, m, deg] (x ahead, y left), mapping as it goes, and "
        f"parks from the last; '' maps standing still only. Default: {DEFAULT_MAPPING_ROUTE} "
        "(0.35 m back)",
    )
    p.add_argument(
        "--no-late-box", action="store_true", help="parking: no box appears (the lot is as mapped)"
    )
    p.add_argument(
        "--timeout",
        type=float,
        default=None,
        help="give up after this many wall seconds (default: parking and loop "
        f"{PARKING_TIMEOUT_S:g}; smart-city {smart_city.TIMEOUT_S:g}, a hang guard: it ends "
        "when every car drove its laps)",
    )
    p.add_argument("--duration", type=float, default=40.0, help="loop: driven time [s, sim time]")
    p.add_argument(
        "--realtime",
        action="store_true",
        help="run in real time (default: lockstep with the runtime, as fast as it keeps up)",
    )
    p.add_argument(
        "--headless",
        action="store_true",
        help="never open the simulator's window (default: open it when a display exists)",
    )
    p.add_argument(
        "--rtf", type=float, help="pace the simulator at this real-time factor instead of lockstep"
    )
    p.add_argument(
        "--cameras",
        type=float,
        default=0.0,
        metavar="FPS",
        help="render every camera (front, rear, the overhead Eye) at FPS [Hz of sim time] "
        "(default 0: only the overhead ones, for --eye cameras, at "
        f"{pose_source.EYE_FPS_DEFAULT:g} Hz)",
    )
    pose_source.add_eye_option(p, default=None)
    p.add_argument("--laps", type=int, default=3, help="smart-city: laps every car drives")
    p.add_argument(
        "--advisory",
        choices=("scm", "standin"),
        default="scm",
        help="smart-city: V2I advisories from autodrive-scm (web app; default) or the small "
        "stand-in publisher (autodrive.hil.city.advisory)",
    )
    p.add_argument(
        "--city-eye",
        choices=("cameras", "standin"),
        help="deprecated: the old name of --eye (smart-city); says so and does what --eye does",
    )
    p.add_argument("--scm-port", type=int, default=8765, help="smart-city: the SCM's web port")
    p.add_argument(
        "--late-obstacles",
        choices=("none", "all"),
        default="none",
        help="smart-city: the map's late boxes: none (default), or all: each stands on a route's "
        "lane for good, the cars stop before them (LIDAR) and the report names the blocked cars",
    )
    p.add_argument(
        "--sim-seconds",
        type=float,
        default=0.0,
        help="smart-city: end after this much sim time [s] (a short run; 0: when every car drove "
        "--laps)",
    )
    p.add_argument("--lcm-url", default=channels.load().url_default, help="LCM URL")
    args = p.parse_args(argv)
    args.lcm_url = instance_lcm_url(p, args.lcm_url)
    if args.city_eye is not None:
        if args.eye is not None and args.eye != args.city_eye:
            p.error(f"--city-eye {args.city_eye} contradicts --eye {args.eye}: give --eye only")
        print(
            f"tools/demo: --city-eye is deprecated, use --eye {args.city_eye} (the one pose-source "
            "flag of every mission)",
            file=sys.stderr,
        )
        args.eye = args.city_eye
    if args.eye is None:
        args.eye = "cameras"
    if args.timeout is None:
        args.timeout = smart_city.TIMEOUT_S if args.mission == "smart-city" else PARKING_TIMEOUT_S
    if args.timeout <= 0:
        p.error(f"--timeout {args.timeout:g}: expected > 0 s")
    if args.cameras < 0:
        p.error(f"--cameras {args.cameras}: the frame rate must be >= 0 Hz")
    return args


def write_runtime_config(out: Path, run_dir: Path, url: str) -> Path:
    """The HIL runtime config with this run's bus and the simulator's ptys."""
    cfg = yaml.safe_load(RUNTIME_HIL_CONFIG.read_text())
    cfg["lcm_url"] = url
    # The runtime stamps and integrates on the sim's SIM_CLOCK: right faster than real time,
    # and also in real time when the sim falls behind (a window, a loaded CPU) and slips.
    cfg["clock"] = "sim"
    cfg["bridge"]["device"] = str(run_dir / "nigel1-nano")
    cfg["lidar"]["device"] = str(run_dir / "nigel1-lidar")
    path = out / "runtime.yaml"
    path.write_text(yaml.safe_dump(cfg, sort_keys=False))
    return path


def sim_argv(
    args: argparse.Namespace,
    build: Path,
    run_dir: Path,
    rtf: float | None,
    plan: Any,
    eye_latency_ms: float | None,
) -> list[object]:
    if args.mission == "loop":
        duration_s = args.duration + LOOP_SIM_MARGIN_S
    else:
        duration_s = args.timeout * max(rtf or PARKING_LOCKSTEP_RTF_BOUND, 1.0)
        duration_s += PARKING_SIM_MARGIN_S
    argv: list[object] = [build / "bin" / "autodrive-sim", "--map", "parking_school"]
    argv += ["--run-dir", run_dir, "--seed", args.seed, "--lcm-url", args.lcm_url]
    argv += ["--duration", duration_s]
    if args.cameras > 0:
        argv += ["--cameras"]  # front and rear, at the overhead camera's rate
    if args.cameras > 0 or args.eye == "cameras":
        argv += ["--eye", "--camera-fps", args.cameras or pose_source.EYE_FPS_DEFAULT]
    # the Eye in lockstep: its poses at capture + L, any load (none: not in lockstep)
    argv += pose_source.sim_sync_argv(eye_latency_ms, args.eye_sync_wait_s)
    if plan is not None:
        argv += ["--no-lidar-lcm"]  # <VEH>_LIDAR comes from the runtime's RPLIDAR driver
        s = plan.start
        argv += ["--start", f"{s[0]:.4f},{s[1]:.4f},{math.degrees(s[2]):.3f}"]
        for box in args.late_box:
            argv += ["--late-box", box]
    # --rtf also at 1: the sim then publishes SIM_CLOCK, which the runtime runs on
    argv += ["--lockstep-client"] if rtf is None else ["--rtf", rtf]
    if (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")) and not args.headless:
        argv += ["--view"]  # a window when a display exists; headless otherwise
    return argv


def start_pose_source(
    args: argparse.Namespace,
    build: Path,
    out: Path,
    procs: ProcessGroup,
    latency_ms: float | None,
) -> str:
    """The car's pose source of --eye on Parking School (its one overhead camera 'eye', the
    config eye/config/sim/eye.yaml), in lockstep with latency_ms unless None; returns what
    runs."""
    fps = args.cameras or pose_source.EYE_FPS_DEFAULT
    if args.eye == "cameras":
        eye_argv = [build / "bin" / "autodrive-eye", "run", "-c", EYE_SIM_CONFIG, "-q"]
        eye_argv += ["--source", f"lcm:{channels.channel('EYE_IMAGE')}"]
        eye_argv += pose_source.eye_lockstep_argv(latency_ms)
        procs.start("autodrive-eye", [*eye_argv, "--lcm-url", args.lcm_url], out / "eye.log")
        return pose_source.describe("cameras", MAP, fps, latency_ms)
    return pose_source.start(
        procs, args.eye, build, MAP, out, args.lcm_url, [VEHICLE], args.seed, fps, latency_ms
    )


def parking_plan(args: argparse.Namespace) -> parking.ParkingPlan:
    """The parking scenario of the options; ValueError naming the bad option."""
    try:
        start = parking.start_pose(args.start, args.seed)
    except ValueError as e:
        raise ValueError(f"--start {args.start}: {e}") from None
    route = parking.mapping_route(args.mapping_route)
    if args.no_late_box:
        args.late_box = []
    elif not args.late_box:
        args.late_box = [DEFAULT_LATE_BOX if route else DEFAULT_LATE_BOX_STILL]
    return parking.ParkingPlan(
        slot=args.slot,
        seed=args.seed,
        start=start,
        timeout_s=args.timeout,
        boxes=parking.late_boxes(args.late_box),
        route=route,
    )


def write_mcap(lcm_log: Path, out: Path, build: Path, say: Callable[[str], None]) -> None:
    """run.mcap beside the LCM log, for Foxglove and ros2 bag; a failed export is reported and
    does not fail the run (the LCM log stays the record)."""
    saved_map = out / "map.yaml"
    try:
        counts = export_mcap.export_mcap(
            lcm_log, out / "run.mcap", build, saved_map if saved_map.is_file() else None
        )
        say(f"wrote {out / 'run.mcap'} ({sum(counts.values())} messages, {len(counts)} topics)")
    except (ValueError, RuntimeError, OSError) as e:
        say(f"run.mcap not written: {e}")


def run(
    args: argparse.Namespace,
    console: TextIO = sys.stdout,
    stop_also: Callable[[], bool] | None = None,
) -> int:
    """Runs the demo; progress on console. Returns 0 ok, 1 not ok, 2 bad input, 130 when
    stopped by a signal or by stop_also."""

    def say(msg: str) -> None:
        print(f"[demo] {msg}", file=console, flush=True)

    def echo(line: str) -> None:
        print(line, file=console, flush=True)

    if args.mission == "smart-city":
        return smart_city.run(args, console, stop_also)
    build, out = Path(args.build), Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    for prog in PROGRAMS:
        if not (build / "bin" / prog).exists():
            say(f"ERROR: {build / 'bin' / prog} is missing: build first (tools/demo does)")
            return 2
    try:  # every command is signed: the car's key must exist before anything starts
        command_auth.load_key(command_auth.default_key_path(VEHICLE))
    except ValueError as e:
        say(f"ERROR: {e}")
        return 2
    # None: lockstep. The sim then steps only while the runtime's bridge keeps writing (its
    # 50 Hz COMMAND stream on SIM_CLOCK), never more than 40 ms of sim time ahead of it.
    rtf = 1.0 if args.realtime else args.rtf
    try:
        plan = parking_plan(args) if args.mission == "parking" else None
    except ValueError as e:
        say(f"ERROR: {e}")
        return 2
    run_dir = Path(f"/tmp/autodrive-demo-{os.getpid()}")
    run_dir.mkdir(parents=True, exist_ok=True)
    cfg_path = write_runtime_config(out, run_dir, args.lcm_url)
    procs = ProcessGroup(say)
    interrupted = False

    def on_signal(_sig: int, _frame: FrameType | None) -> None:
        nonlocal interrupted
        interrupted = True

    def stop_requested() -> bool:
        nonlocal interrupted
        interrupted = interrupted or (stop_also is not None and stop_also())
        return interrupted

    old_handlers = [(s, signal.signal(s, on_signal)) for s in (signal.SIGINT, signal.SIGTERM)]
    lcm_log = out / "run.lcmlog"
    t_wall0 = time.time()
    result: dict[str, Any] = {}
    eye_what = "not started"
    eye_latency = pose_source.lockstep_latency_ms(args, lockstep=rtf is None)
    ctx = MissionContext(build, out, args.lcm_url, VEHICLE, procs, stop_requested, say, echo)
    try:
        logger_argv = lcmtypes.logger_argv(args.lcm_url, "-f", "--flush-interval=100")
        procs.start("lcm-logger", [*logger_argv, lcm_log], out / "lcm-logger.log")
        sim = sim_argv(args, build, run_dir, rtf, plan, eye_latency)
        procs.start("autodrive-sim", sim, out / "sim.log")
        wait_for_path(run_dir / "nigel1-nano", PTY_TIMEOUT_S, procs)
        eye_what = start_pose_source(args, build, out, procs, eye_latency)
        runtime = build / "bin" / "autodrive-runtime"
        procs.start("autodrive-runtime", [runtime, "--config", cfg_path], out / "runtime.log")
        if plan is None:  # on the map filter; without an Eye (no map fix) on the odometry
            pose_channel = "ODOM" if args.eye == "none" else "POSE_MAP"
            result = loop.drive(ctx, args.duration, rtf, pose_channel)
        else:
            result = parking.run(ctx, plan)
    except RuntimeError as e:
        say(f"ERROR: {e}")
        result = {"error": str(e)}
    finally:
        exits = procs.stop_all()
        shutil.rmtree(run_dir, ignore_errors=True)
        for s, h in old_handlers:
            signal.signal(s, h)
    wall_s = time.time() - t_wall0
    stop_requested()
    if interrupted:
        say("interrupted: everything stopped; analysing what was recorded")
    give_ups = pose_source.eye_sync_give_ups(out / "sim.log", eye_latency)
    rep = report.analyse(lcm_log, out, VEHICLE, build, args.eye, eye_what, eye_latency, give_ups)
    rep.update(result)
    if plan is not None and "goal_world" in result:
        rep.update(parking.score(lcm_log, out, VEHICLE, build, result))
        # A run with any foreign command on the bus is not a success, even if the car parked.
        rep["mission_success"] = bool(rep.get("success"))
        rep["success"] = rep["mission_success"] and rep.get("foreign_commands", 0) == 0
        rep["ok"] = bool(rep.get("success")) and rep.get("collisions", 1) == 0
    if rep.get("foreign_commands"):
        say(
            f"WARNING: the bridge dropped {rep['foreign_commands']} foreign command(s) "
            f"(unsigned {rep.get('foreign_unsigned')}, bad signature "
            f"{rep.get('foreign_bad_signature')}, replayed {rep.get('foreign_replayed')}): "
            "not a success"
        )
    record_children(rep, exits, say)
    pose_source.eye_sync_verdict(rep, say=say)  # a run that depended on wall time fails
    rep["wall_s"] = round(wall_s, 2)
    rep["rtf_requested"] = rtf if rtf is not None else "lockstep"
    if rep.get("sim_s") and wall_s > 0:
        rep["rtf_achieved"] = round(rep["sim_s"] / wall_s, 2)
    (out / "report.json.tmp").write_text(json.dumps(rep, indent=2))
    os.replace(out / "report.json.tmp", out / "report.json")
    say(f"report: {json.dumps(rep)}")
    say(pose_source.summary_line(rep))
    pngs = ", ".join(p.name for p in sorted(out.glob("*.png")))
    say(f"wrote {out}/report.json, plots {pngs}, log {lcm_log}")
    write_mcap(lcm_log, out, build, say)
    if interrupted:
        return EXIT_INTERRUPTED
    if not rep.get("ok"):
        say(f"FAILED: {rep.get('error', 'see report.json')}")
    return 0 if rep.get("ok") else 1


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    if any(a in ("--mission=cloning", "cloning") for a in args) and "--mission" in " ".join(args):
        from autodrive.hil.missions import cloning  # its own options (--laps, --condition, --model)

        return cloning.main(args)
    if "intersection" in args and ("--mission" in args or "--mission=intersection" in args):
        from autodrive.hil.missions import (
            intersection,
        )  # its own options (--episodes, --v2v-loss, ...)

        return intersection.main(args)
    return run(parse_args(args))


if __name__ == "__main__":
    sys.exit(main())
