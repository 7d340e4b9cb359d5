#!/usr/bin/env python3
"""HIL demo orchestrator: starts the simulator (Parking School), the unchanged Jetson runtime
on the simulator's ptys, a driver, and lcm-logger; stops everything cleanly (also on Ctrl-C);
then writes out/demo/: report.json, PNG plots and the LCM log of the run."""
import argparse
import json
import math
import os
import pathlib
import shutil
import signal
import subprocess
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent
# The default scenario's unmapped box (x, y [m], T [s], half sizes [m], R [m]), on the direct
# way from the spawn to slot 2. After a mapping route it steps out once the car
# comes back within 0.5 m of it, and not before 8 s of sim time: the car starts within 0.5 m
# of it, and a slow start of the route (a loaded machine, ASan) must not let the mapping see it;
# mapping standing still, it appears at 3.5 s, after the map is saved.
DEFAULT_LATE_BOX = "-0.62,0.76,8,0.06,0.06,0.5"
DEFAULT_LATE_BOX_STILL = "-0.62,0.76,3.5"
DEFAULT_MAPPING_ROUTE = "-0.35,0,0"


def log(msg):
    print(f"[demo] {msg}", flush=True)


def parse_args():
    p = argparse.ArgumentParser(
        prog="tools/demo",
        description="Run the Nigel HIL demo: autodrive-sim (Parking School) + the unchanged "
        "autodrive-runtime on its ptys + a driver, recorded with lcm-logger. Writes "
        "out/demo/{report.json,*.png,run.lcmlog}.",
    )
    p.add_argument("--build", default=str(ROOT / "build" / "release"), help="host build dir")
    p.add_argument("--out", default=str(ROOT / "out" / "demo"), help="output folder")
    p.add_argument(
        "--seed",
        type=int,
        default=1,
        help="scenario seed: sensor noise, IMU biases, AMCL, and the start pose (see --start)",
    )
    p.add_argument(
        "--mission",
        choices=("parking", "loop"),
        default="parking",
        help="parking (default): map, localise, plan and park autonomously; loop: "
        "drive a stadium track with pure pursuit on the EKF",
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
        "--timeout", type=float, default=240.0, help="parking: give up after this many wall seconds"
    )
    p.add_argument("--duration", type=float, default=40.0, help="loop: driven time [s, sim time]")
    p.add_argument(
        "--realtime",
        action="store_true",
        help="run in real time (default: lockstep with the runtime, as fast as it " "keeps up)",
    )
    p.add_argument(
        "--headless",
        action="store_true",
        help="never open the simulator's window (default: open it when a display exists)",
    )
    p.add_argument(
        "--rtf", type=float, help="pace the simulator at this real-time factor instead of lockstep"
    )
    p.add_argument("--lcm-url", default="udpm://239.255.76.67:7667?ttl=0", help="LCM URL")
    return p.parse_args()


class Procs:
    """Child processes, stopped in reverse start order with SIGINT, then SIGKILL."""

    def __init__(self):
        self.items = []

    def start(self, name, argv, logfile):
        log(f"starting {name}: {' '.join(map(str, argv))}")
        f = open(logfile, "w")
        proc = subprocess.Popen(
            [str(a) for a in argv], stdout=f, stderr=subprocess.STDOUT, start_new_session=True
        )
        self.items.append((name, proc, f))
        return proc

    def check(self):
        for name, proc, f in self.items:
            if proc.poll() is not None and proc.returncode != 0:
                raise RuntimeError(f"{name} exited with code {proc.returncode} (log: {f.name})")

    def stop_all(self):
        for name, proc, f in reversed(self.items):
            if proc.poll() is None:
                proc.send_signal(signal.SIGINT)
                try:
                    proc.wait(timeout=5)
                except subprocess.TimeoutExpired:
                    log(f"{name} did not stop on SIGINT; killing it")
                    proc.kill()
                    proc.wait()
            f.close()
        self.items.clear()


def wait_for(path, timeout_s, procs):
    t0 = time.time()
    while not os.path.exists(path):
        procs.check()
        if time.time() - t0 > timeout_s:
            raise RuntimeError(f"{path} did not appear within {timeout_s} s")
        time.sleep(0.05)


def main():
    args = parse_args()
    build = pathlib.Path(args.build)
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    run_dir = pathlib.Path(f"/tmp/autodrive-demo-{os.getpid()}")
    run_dir.mkdir(parents=True, exist_ok=True)
    for prog in ("autodrive-sim", "autodrive-runtime", "autodrive-autonomy"):
        if not (build / "bin" / prog).exists():
            sys.exit(
                f"[demo] ERROR: {build / 'bin' / prog} is missing: build first (tools/demo does)"
            )
    # None: lockstep. The sim then steps only while the runtime's bridge keeps writing (its
    # 50 Hz COMMAND stream on SIM_CLOCK), never more than 40 ms of sim time ahead of it.
    rtf = 1.0 if args.realtime else args.rtf
    if rtf is None and args.mission == "loop":
        rtf = 2.0  # the loop driver commands at 50 Hz of wall time: keep the sim paced
    import demo_parking  # noqa: E402  (tools/demo_parking.py)

    try:
        start = demo_parking.start_pose(args.start, args.seed)
    except ValueError as e:
        sys.exit(f"[demo] ERROR: --start {args.start}: {e}")
    try:
        mapping_route = demo_parking.mapping_route(args.mapping_route)
    except ValueError as e:
        sys.exit(f"[demo] ERROR: {e}")
    sys.path.insert(0, str(build / "lcm_types" / "gen" / "python"))
    import yaml  # noqa: E402

    cfg = yaml.safe_load((ROOT / "runtime/jetson/config/nigel_hil.yaml").read_text())
    cfg["lcm_url"] = args.lcm_url
    # The runtime stamps and integrates on the sim's SIM_CLOCK: right faster than real time, and
    # also in real time when the sim falls behind (a window, a loaded CPU) and slips.
    cfg["clock"] = "sim"
    cfg["bridge"]["device"] = str(run_dir / "nigel1-nano")
    cfg["lidar"]["device"] = str(run_dir / "nigel1-lidar")
    cfg_path = out / "runtime.yaml"
    cfg_path.write_text(yaml.safe_dump(cfg, sort_keys=False))

    import demo_driver  # noqa: E402  (tools/demo_driver.py)

    procs = Procs()
    interrupted = False

    def on_sigint(_sig, _frm):
        nonlocal interrupted
        interrupted = True

    signal.signal(signal.SIGINT, on_sigint)
    signal.signal(signal.SIGTERM, on_sigint)

    lcm_log = out / "run.lcmlog"
    t_wall0 = time.time()
    result = {}
    try:
        procs.start(
            "lcm-logger",
            ["lcm-logger", f"--lcm-url={args.lcm_url}", "-f", "--flush-interval=100", lcm_log],
            out / "lcm-logger.log",
        )
        sim_argv = [
            build / "bin" / "autodrive-sim",
            "--map",
            "parking_school",
            "--run-dir",
            run_dir,
            "--seed",
            args.seed,
            "--lcm-url",
            args.lcm_url,
            "--duration",
            (args.duration + 8.0)
            if args.mission == "loop"
            else args.timeout * max(rtf or 20.0, 1.0) + 30.0,
        ]
        if args.mission == "parking":
            sim_argv += ["--no-lidar-lcm"]  # <VEH>_LIDAR comes from the runtime's RPLIDAR driver
            sim_argv += ["--start", f"{start[0]:.4f},{start[1]:.4f},{math.degrees(start[2]):.3f}"]
            if not args.late_box and not args.no_late_box:
                args.late_box = [DEFAULT_LATE_BOX if mapping_route else DEFAULT_LATE_BOX_STILL]
            if args.no_late_box:
                args.late_box = []
            for box in args.late_box:
                sim_argv += ["--late-box", box]
        # --rtf also at 1: the sim then publishes SIM_CLOCK, which the runtime runs on
        sim_argv += ["--lockstep-client"] if rtf is None else ["--rtf", rtf]
        if (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")) and not args.headless:
            sim_argv += ["--view"]  # a window when a display exists; headless otherwise
        procs.start("autodrive-sim", sim_argv, out / "sim.log")
        wait_for(run_dir / "nigel1-nano", 30, procs)
        procs.start(
            "autodrive-runtime",
            [build / "bin" / "autodrive-runtime", "--config", cfg_path],
            out / "runtime.log",
        )
        if args.mission == "loop":
            result = demo_driver.drive(
                args.lcm_url, "NIGEL1", args.duration, rtf, procs, lambda: interrupted
            )
        else:
            result = demo_parking.run(
                build,
                out,
                args.lcm_url,
                args.slot,
                args.seed,
                start,
                args.timeout,
                procs,
                lambda: interrupted,
                demo_parking.late_boxes(args.late_box),
                mapping_route,
            )
    except RuntimeError as e:
        log(f"ERROR: {e}")
        result = {"error": str(e)}
    finally:
        procs.stop_all()
        shutil.rmtree(run_dir, ignore_errors=True)
    wall_s = time.time() - t_wall0
    if interrupted:
        log("interrupted: everything stopped; analysing what was recorded")
    import demo_report  # noqa: E402  (tools/demo_report.py)

    report = demo_report.analyse(lcm_log, out, "NIGEL1")
    report.update(result)
    if args.mission == "parking" and "goal_world" in result:
        report.update(demo_parking.score(lcm_log, out, "NIGEL1", result))
        report["ok"] = bool(report.get("success")) and report.get("collisions", 1) == 0
    report["wall_s"] = round(wall_s, 2)
    report["rtf_requested"] = rtf if rtf is not None else "lockstep"
    if report.get("sim_s") and wall_s > 0:
        report["rtf_achieved"] = round(report["sim_s"] / wall_s, 2)
    (out / "report.json.tmp").write_text(json.dumps(report, indent=2))
    os.replace(out / "report.json.tmp", out / "report.json")
    log(f"report: {json.dumps(report)}")
    log(
        f"wrote {out}/report.json, plots {', '.join(p.name for p in sorted(out.glob('*.png')))}, "
        f"log {lcm_log}"
    )
    if interrupted:
        return 130
    if not report.get("ok"):
        log(f"FAILED: {report.get('error', 'see report.json')}")
    return 0 if report.get("ok") else 1


if __name__ == "__main__":
    sys.path.insert(0, str(ROOT / "tools"))
    sys.exit(main())
