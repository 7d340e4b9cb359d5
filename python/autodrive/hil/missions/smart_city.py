"""The smart-city mission (tools/demo --mission smart-city): Tiny Town with three cars on looping
routes through its lights and signs. Starts autodrive-sim (3 cars, lockstep with the runtimes),
three unchanged autodrive-runtime processes on its ptys (V2V on), the car poses (--eye, see
autodrive.hil.pose_source: by default autodrive-eye on the map's four overhead cameras, which
the simulator renders at --cameras FPS, EYE_FPS_DEFAULT unless given; each EKF starts from its
car's first Eye fix, and the car waits still until then), each car's <VEH>_POSE_EYE fused by its
runtime's EKF, the Smart City Manager
(autodrive-scm: web app, database, V2I advisories; --advisory standin uses the small advisory
publisher instead), three autodrive-city-driver processes and lcm-logger. The run is scored
from the simulator's ground truth and light states (autodrive.hil.city.scoring) while it
runs, with each EKF's error against the truth: report.json, trajectories.png (paths and light
phases) and run.lcmlog in --out."""

from __future__ import annotations

import argparse
import json
import math
import os
import random
import select
import shutil
import signal
import sys
import time
import urllib.request
from pathlib import Path
from types import FrameType
from typing import Any, TextIO

from autodrive.core import command_auth, lcmtypes, v2x_ca
from autodrive.maps import eye_cameras
from autodrive.core.channels import channel, vehicle_name
from autodrive.hil import pose_source
from autodrive.hil.city import hil
from autodrive.hil.city.scoring import BLOCKED_S, MapFacts, Scorer
from autodrive.maps.loader import MAPS_DIR
from autodrive.core.settings import OUT_DIR
from autodrive.core.proc import ProcessGroup, wait_ready
from autodrive.hil.missions import EXIT_INTERRUPTED, record_children

MAP = "tiny_town"
# One looping route of the map per car: north through light 3 and the stop sign; south through
# light 1 and a curve sign; round the town past the speed-limit and curve signs.
ROUTES = ("city_east", "city_west", "loop_ccw")
START_SPREAD_M = 1.0  # each car starts up to this far along its route from its start [m]
PROGRESS_S = 10.0
MAX_BATCH = 500  # LCM messages handled between two looks at the run's state
# The map's late boxes are out by default (--late-obstacles all puts them in): each stands on a
# route's lane for good once it appeared, so the car behind it stops and waits for ever, and 3
# laps each cannot be. late_box_0 appears in the middle of the crossroads road c1, 0.065 m from
# both lane centres (less than half a car's width): it blocks city_east and city_west; late_box_1
# stands on the centre line of w2_n_s, loop_ccw's lane. The report then names the blocked cars.
# The overhead cameras' frame rate [Hz of sim time]. The cars drive at most 0.27 m/s, so 5 Hz
# is <= 54 mm between poses, which the EKF bridges with odometry and gyro; each frame time is
# four 1280x960 renders (~160 ms of CPU with software OpenGL), which is what 2 shared cores can
# give beside three runtimes (docs/results/smart-city.md: the figures were measured at 5 Hz).
EYE_FPS_DEFAULT = pose_source.EYE_FPS_DEFAULT
# Starting up is bounded by each program's own CPU time, not by wall time (on a loaded machine
# the wall time of a start is anyone's guess: at load 48 the SCM was not up in 90 s). Measured
# here (2026-11-27, load ~10): the SCM is ready after 1.2-1.3 s of its CPU (Python, FastAPI,
# SQLAlchemy, Alembic; its pose receiver is a process of its own, not counted) and the simulator
# has its ptys after 0.1 s of its CPU; the budgets are far above that, so that only a start
# that really is stuck fails. --timeout [s wall] bounds the whole run, the start too.
SCM_START_CPU_S = 30.0
SIM_START_CPU_S = 60.0
TIMEOUT_S = 3600.0  # the default --timeout [s wall]: a hang guard, the run ends at its laps
OVERSHOOT_GOAL_M = 0.03  # a car stops at most this far past its stop line [m]
EKF_P95_GOAL_M = 0.02  # on the real Eye, every car's EKF error p95 against ground truth [m]
NANO_FAILSAFE = 2  # vehicle_state_t.mode: the Nano's latched failsafe


def why_blocked(cars: list[str], nano_modes: dict[str, int]) -> str:
    """Why cars stand for good: a Nano in its latched failsafe ignores the commands, else an
    obstacle on the lane holds them."""
    latched = [c for c in cars if nano_modes.get(c) == NANO_FAILSAFE]
    if latched:
        return f"the Nano of {latched} is in its latched failsafe: its command stream had a gap"
    return "an obstacle on the lane"


def scm_ready(base_url: str) -> str | None:
    """None when the SCM answers /api/status with ready true; else what it answered."""
    try:
        with urllib.request.urlopen(base_url + "api/status", timeout=5) as r:
            body = json.loads(r.read())
    except (OSError, ValueError) as err:  # not listening yet, or a half-started server
        return f"GET {base_url}api/status: {err}"
    return None if body.get("ready") is True else f"GET {base_url}api/status: {body}"


def start_poses(seed: int) -> list[tuple[float, float, float]]:
    """Each car's marked start on its route (the route's polyline), moved along it by the
    seed."""
    routes = {r["name"]: r for r in json.loads((MAPS_DIR / f"{MAP}.json").read_text())["routes"]}
    rng = random.Random(seed)
    poses = []
    for name in ROUTES:
        pts = routes[name]["polyline_m"]
        k = int(rng.uniform(0.0, START_SPREAD_M) / 0.05)
        (x0, y0), (x1, y1) = pts[k], pts[k + 1]
        poses.append((x0, y0, math.atan2(y1 - y0, x1 - x0)))
    return poses


def ensure_keys(cars: int, say: Any) -> None:
    """The cars' command keys and the testbed certificates (V2V, V2I, lights, Eye poses)."""
    v2x_ca.ensure_run_keys([vehicle_name(i) for i in range(1, cars + 1)], say)


def plot(
    out: Path,
    tracks: dict[str, list[tuple[float, float, float]]],
    phases: dict[int, list[tuple[float, int]]],
    facts: MapFacts,
) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax, bx) = plt.subplots(2, 1, figsize=(9, 11), gridspec_kw={"height_ratios": [3, 1]})
    for pts in facts.lanes.values():
        ax.plot([p["x_m"] for p in pts], [p["y_m"] for p in pts], color="0.85", lw=0.8)
    for car, tr in sorted(tracks.items()):
        ax.plot([p[1] for p in tr], [p[2] for p in tr], lw=1.2, label=car)
    for s in facts.stops:
        ax.plot(s.x_m, s.y_m, "s", color="red" if s.light_id >= 0 else "darkred", ms=5)
        ax.annotate(
            f"light {s.light_id}" if s.light_id >= 0 else "stop", (s.x_m, s.y_m), fontsize=7
        )
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.legend()
    ax.set_title("smart city: ground-truth paths, stop lines of lights and stop signs")
    colours = {0: "0.3", 1: "red", 2: "gold", 3: "green"}
    for row, (lid, ph) in enumerate(sorted(phases.items())):
        for (t0, st), (t1, _) in zip(ph, ph[1:] + [(ph[-1][0] + 0.1, 0)]):
            bx.barh(row, t1 - t0, left=t0, color=colours.get(st, "0.5"), height=0.8)
    bx.set_yticks(range(len(phases)), [f"light {k}" for k in sorted(phases)])
    bx.set_xlabel("sim time [s]")
    bx.set_title("light phases (ground truth: TRAFFIC_LIGHT_STATE)")
    fig.tight_layout()
    fig.savefig(out / "trajectories.png", dpi=110)
    plt.close(fig)


def run(args: argparse.Namespace, console: TextIO = sys.stdout, stop_also: Any = None) -> int:
    def say(msg: str) -> None:
        print(f"[smart-city] {msg}", file=console, flush=True)

    build = Path(args.build)
    out = Path(args.out)
    if out == OUT_DIR / "demo":  # the demo's default folder: this mission's own
        out = OUT_DIR / "demo-smart-city"
    out.mkdir(parents=True, exist_ok=True)
    for prog in ("autodrive-sim", "autodrive-runtime", "autodrive-city-driver"):
        if not (build / "bin" / prog).exists():
            say(f"ERROR: {build / 'bin' / prog} is missing: build first (tools/demo does)")
            return 2
    cars = len(ROUTES)
    ensure_keys(cars, say)
    url = args.lcm_url
    starts = start_poses(args.seed)
    run_dir = Path(f"/tmp/autodrive-city-{os.getpid()}")
    run_dir.mkdir(parents=True, exist_ok=True)
    procs = ProcessGroup(say)
    interrupted = False

    def on_signal(_s: int, _f: FrameType | None) -> None:
        nonlocal interrupted
        interrupted = True

    old = [(s, signal.signal(s, on_signal)) for s in (signal.SIGINT, signal.SIGTERM)]
    facts = MapFacts.load(MAPS_DIR / f"{MAP}.json")
    scorer = Scorer(facts, blocked_s=BLOCKED_S)
    tracks: dict[str, list[tuple[float, float, float]]] = {}
    phases: dict[int, list[tuple[float, int]]] = {}
    sim_t = [0.0]
    poses = pose_source.PoseRecord()
    eye_what = "not started"
    eye_latency: float | None = None
    result: dict[str, Any] = {}
    t_wall0 = time.time()
    scm_url = ""
    try:
        types = lcmtypes.load(build)
        lc = lcmtypes.bus(url)

        def on_truth(_ch: str, data: bytes) -> None:
            m = types.ground_truth_t.decode(data)
            t = m.utime * 1e-6
            sim_t[0] = max(sim_t[0], t)
            x, y = m.position_m[0], m.position_m[1]
            poses.on_truth(m.vehicle, t, x, y)
            scorer.truth(m.vehicle, t, x, y, m.yaw_rad, m.in_collision)
            tr = tracks.setdefault(m.vehicle, [])
            if not tr or t - tr[-1][0] >= 0.1:
                tr.append((t, x, y))

        def on_light(_ch: str, data: bytes) -> None:
            m = types.traffic_light_state_t.decode(data)
            scorer.light(m.light_id, m.state)
            ph = phases.setdefault(m.light_id, [])
            if not ph or ph[-1][1] != m.state:
                ph.append((m.utime * 1e-6, m.state))

        nano_modes: dict[str, int] = {}  # each car's Nano mode (vehicle_state_t.mode)

        state_channels = {
            channel("STATE", vehicle_name(i)): vehicle_name(i) for i in range(1, cars + 1)
        }

        def on_state(ch: str, data: bytes) -> None:  # the message names no car: its channel does
            nano_modes[state_channels[ch]] = types.vehicle_state_t.decode(data).mode

        for i in range(1, cars + 1):
            lc.subscribe(channel("GROUND_TRUTH", vehicle_name(i)), on_truth)
            lc.subscribe(channel("STATE", vehicle_name(i)), on_state)
        lc.subscribe(channel("TRAFFIC_LIGHT_STATE"), on_light)

        def on_eye(_ch: str, data: bytes) -> None:
            m = types.pose2d_t.decode(data)
            poses.on_eye(m.vehicle, m.utime * 1e-6)

        def on_ekf(_ch: str, data: bytes) -> None:
            m = types.odometry_t.decode(data)
            poses.on_ekf(m.vehicle, m.utime * 1e-6, m.x_m, m.y_m)

        for i in range(1, cars + 1):
            lc.subscribe(channel("POSE_EYE", vehicle_name(i)), on_eye)
            lc.subscribe(channel("POSE_MAP", vehicle_name(i)), on_ekf)
        logger = lcmtypes.logger_argv(url, "-f", "--flush-interval=100")
        procs.start("lcm-logger", [*logger, out / "run.lcmlog"], out / "lcm-logger.log")
        sim: list[object] = [build / "bin" / "autodrive-sim", "--map", MAP, "--cars", cars]
        for x, y, yaw in pose_source.placed(starts, args.eye, args.seed):
            sim += ["--start", f"{x:.4f},{y:.4f},{math.degrees(yaw):.3f}"]
        if args.late_obstacles == "none":
            sim += ["--no-late-obstacles"]
        sim += ["--seed", args.seed, "--run-dir", run_dir, "--lcm-url", url]
        # --rtf X (tools/demo): paced at X real time; else in lockstep with the runtimes
        pacing = ["--rtf", args.rtf] if args.rtf else ["--lockstep-client"]
        sim += [*pacing, "--duration", 3600]
        eye_fps = args.cameras or EYE_FPS_DEFAULT
        # in lockstep the Eye is too: its poses at capture + L of sim time, at any load
        eye_latency = pose_source.lockstep_latency_ms(args, lockstep=not args.rtf)
        sim += pose_source.sim_argv(args.eye, eye_fps, eye_latency, args.eye_sync_wait_s)
        if (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")) and not args.headless:
            sim += ["--view"]
        sim_proc = procs.start("autodrive-sim", sim, out / "sim.log")
        nano = run_dir / f"{vehicle_name(cars).lower()}-nano"
        sim_cpu_s = wait_ready(
            "autodrive-sim",
            sim_proc,
            lambda: None if nano.exists() else f"no {nano} yet",
            procs,
            SIM_START_CPU_S,
            args.timeout,
            say,
            out / "sim.log",
        )
        say(f"autodrive-sim has its ptys (after {sim_cpu_s:.1f} s of its CPU)")
        py = sys.executable
        names = [vehicle_name(i) for i in range(1, cars + 1)]
        vehicles = ",".join(names)
        eye_what = pose_source.start(
            procs, args.eye, build, MAP, out, url, names, args.seed, eye_fps, eye_latency
        )
        for i in range(1, cars + 1):
            # the EKF's start: its first Eye fix, or (--eye none) the marked start pose
            given = starts[i - 1] if args.eye == "none" else None
            cfg = hil.runtime_config(out, run_dir, url, i, given, ROUTES[i - 1], lidar=True)
            procs.start(
                f"runtime{i}",
                [build / "bin" / "autodrive-runtime", "--config", cfg],
                out / f"runtime{i}.log",
            )
        if args.advisory == "scm":
            port = args.scm_port
            scm = [
                py,
                "-m",
                "autodrive.scm.cli",
                "--map",
                MAP,
                "--db",
                f"sqlite:///{(out / 'scm.sqlite').resolve()}",
                "--host",
                "127.0.0.1",
                "--port",
                port,
                "--lcm-url",
                url,
                "--vehicles",
                vehicles,
                "--clock",  # yellow and all-red last their time in the simulated town
                "sim",
                "--build",
                build,
            ]
            scm_proc = procs.start("autodrive-scm", scm, out / "scm.log")
            scm_url = f"http://127.0.0.1:{port}/"
            cpu_s = wait_ready(
                "autodrive-scm",
                scm_proc,
                lambda: scm_ready(scm_url),
                procs,
                SCM_START_CPU_S,
                args.timeout,
                say,
                out / "scm.log",
            )
            say(f"Smart City Manager web app: {scm_url} (ready after {cpu_s:.1f} s of its CPU)")
        else:
            adv = [py, "-m", "autodrive.hil.city.advisory", "--map", MAP, "--vehicles", vehicles]
            adv += ["--routes", ",".join(ROUTES[i - 1] for i in range(1, cars + 1))]
            procs.start(
                "advisory", [*adv, "--lcm-url", url, "--build", build], out / "advisory.log"
            )
        for i in range(1, cars + 1):
            drv = [build / "bin" / "autodrive-city-driver", "--map", MAPS_DIR / f"{MAP}.json"]
            drv += ["--route", ROUTES[i - 1], "--vehicle", vehicle_name(i), "--lcm-url", url]
            drv += ["--clock", "sim"]  # advisories' and peers' age in sim time, at any speed
            procs.start(f"city-driver{i}", drv, out / f"city-driver{i}.log")
        say(f"driving {args.laps} laps each (timeout {args.timeout:g} s wall) ...")
        last = time.monotonic()
        while True:
            if interrupted or (stop_also is not None and stop_also()):
                interrupted = True
                break
            procs.check(clean_exit_fails=True)
            # every message waiting (ground truth of 3 cars, light states), so that the scoring
            # keeps up with the bus and misses no stop-line crossing, then the checks below
            timeout_s = 0.1
            for _ in range(MAX_BATCH):
                if not select.select([lc.fileno()], [], [], timeout_s)[0]:
                    break
                lc.handle()
                timeout_s = 0.0
            rep = scorer.report()
            if scorer.cars and len(scorer.cars) == cars and rep["laps_completed"] >= args.laps:
                say(f"every car drove {args.laps} laps")
                break
            if args.sim_seconds > 0 and sim_t[0] >= args.sim_seconds:
                say(f"{args.sim_seconds:g} s of sim time driven (--sim-seconds)")
                break
            if time.time() - t_wall0 > args.timeout:
                result["error"] = f"timeout after {args.timeout:g} s wall"
                say(result["error"])
                break
            if rep["blocked"]:
                result[
                    "error"
                ] = f"blocked for good: {rep['blocked']} ({why_blocked(rep['blocked'], nano_modes)})"
                say(result["error"])
                break
            if time.monotonic() - last > PROGRESS_S:
                last = time.monotonic()
                say(
                    f"t_sim={sim_t[0]:6.1f} s laps {rep['laps_per_car']} red {rep['red_light_violations']} "
                    f"stop {rep['stop_sign_violations']} collisions {rep['collisions']} "
                    f"overshoot {rep['max_stop_line_overshoot_m']:.3f} m"
                )
    except RuntimeError as e:
        say(f"ERROR: {e}")
        result["error"] = str(e)
    finally:
        exits = procs.stop_all()
        shutil.rmtree(run_dir, ignore_errors=True)
        for s, h in old:
            signal.signal(s, h)
    rep = scorer.report()
    rep.update(result)
    rep.update(
        seed=args.seed,
        routes=list(ROUTES),
        sim_s=round(sim_t[0], 1),
        wall_s=round(time.time() - t_wall0, 1),
        advisory=args.advisory,
        scm_url=scm_url,
        late_obstacles=args.late_obstacles,
    )
    rep.update(
        pose_source.report(
            args.eye,
            eye_what,
            [poses],
            [vehicle_name(i) for i in range(1, cars + 1)],
            eye_latency,
            pose_source.eye_sync_give_ups(out / "sim.log", eye_latency),
        )
    )
    rep["ok"] = (
        "error" not in rep
        and not interrupted
        and rep["red_light_violations"] == 0
        and rep["stop_sign_violations"] == 0
        and rep["collisions"] == 0
        and rep["max_stop_line_overshoot_m"] <= OVERSHOOT_GOAL_M
        and rep["laps_completed"] >= args.laps
        and (
            rep["pose_source"] != "eye"
            or (rep["ekf_error_p95_worst_m"] or math.inf) <= EKF_P95_GOAL_M
        )
    )
    pose_source.eye_sync_verdict(rep, say=say)  # a run that depended on wall time fails
    record_children(rep, exits, say)
    (out / "report.json").write_text(json.dumps(rep, indent=2))
    if tracks:
        plot(out, tracks, phases, facts)
    say(f"report: {json.dumps({k: v for k, v in rep.items() if k != 'violations'})}")
    say(pose_source.summary_line(rep))
    say(f"wrote {out}/report.json, trajectories.png, run.lcmlog")
    if interrupted:
        return EXIT_INTERRUPTED
    return 0 if rep["ok"] else 1
