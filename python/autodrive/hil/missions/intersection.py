"""Intersection School in HIL: four cars cross the 4-way intersection, each with the unchanged
autodrive-runtime on its own emulated Nano pty and its own autodrive-marl (the learned policy
or the first-come-first-served baseline, behind the TTC shield), V2V over real LCM.

One episode = one fresh set of processes (the simulator with the four cars placed by
--car-start, four runtimes, four autodrive-marl), so nothing of an episode leaks into the next:
that is the reset. Routes and spawns are drawn from the seed as in training (autodrive.learn.marl.env): one car
per approach, each turning left, going straight or right, a later spawn further back. The simulator runs in lockstep with the runtimes (--lockstep-client),
so a loaded machine slows the run down and does not change it much.

Localisation: in the lab the overhead Eye localises every car; here too, by default (--eye
cameras): the simulator renders Intersection School's two overhead cameras (the map's
eye_cameras) and autodrive-eye publishes each car's <VEH>_POSE_EYE from them, which the unchanged
runtimes' EKFs fuse; each EKF starts from its car's first Eye fix and the car waits still until
then. --eye standin is the test double (ground truth + the Eye's noise); --eye none leaves the
EKFs on dead reckoning from the marked start pose (autodrive.hil.pose_source).

CLI: tools/demo --mission intersection --help."""

from __future__ import annotations

import argparse
import json
import math
import os
import select
import shutil
import signal
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from types import FrameType
from typing import Any

import numpy as np
import yaml

from autodrive.core import channels, lcmtypes, v2x_ca
from autodrive.gym import tasks
from autodrive.learn.marl import env as marl_env
from autodrive.core.settings import RUNTIME_HIL_CONFIG, settings
from autodrive.core.proc import ChildExit, ProcessGroup, wait_for_path
from autodrive.hil import pose_source
from autodrive.hil.missions import (
    EXIT_INTERRUPTED,
    PTY_TIMEOUT_S,
    add_run_options,
    instance_lcm_url,
    record_children,
)

MAP = tasks.INTERSECTION_MAP
MAP_JSON = tasks.MAPS_DIR / f"{MAP}.json"
DEFAULT_POLICY = settings().models_dir / "marl" / "intersection.onnx"
CARS = 4
EPISODE_SIM_S = 90.0  # an episode that has not ended by then is a failure [s of sim time]
# A car is truly at its goal when its ground truth is within this of it when its EKF says so:
# the policy's goal tolerance plus what the Eye-fused EKF may be off by [m].
GOAL_TRUE_TOLERANCE_M = marl_env.GOAL_REACHED_M + 0.05
PLOT_HALF_M = 3.6  # the plots show the map this far around the centre [m]


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    p = argparse.ArgumentParser(
        prog="tools/demo --mission intersection",
        description="Intersection School in HIL: autodrive-sim with four cars, four unchanged "
        "autodrive-runtime processes on their ptys, four autodrive-marl processes, V2V over "
        "real LCM; N seeded episodes. Writes OUT/report.json and OUT/trajectories.png.",
    )
    add_run_options(p, "intersection", "seed of routes, start times and noise", 3600.0)
    p.add_argument("--episodes", type=int, default=20, help="episodes to run (default 20)")
    p.add_argument(
        "--policy",
        choices=("rl", "baseline"),
        default="rl",
        help="rl: the learned policy; baseline: first come, first served on the conflict zone",
    )
    p.add_argument(
        "--policy-file", default=str(DEFAULT_POLICY), help="rl: the policy NAME.onnx (+ NAME.json)"
    )
    p.add_argument("--no-shield", action="store_true", help="send commands unshielded")
    p.add_argument("--v2v-loss", type=float, default=0.0, help="V2V loss probability [0, 1]")
    p.add_argument("--v2v-delay-ms", type=float, default=0.0, help="V2V delay [ms]")
    p.add_argument(
        "--shield-pose-error-m",
        type=float,
        default=0.0,
        help="how far each car's EKF pose may be off [m]: the shield grows every footprint by it",
    )
    pose_source.add_eye_option(p)
    p.add_argument(
        "--cameras",
        type=float,
        default=0.0,
        metavar="FPS",
        help="--eye cameras: the overhead cameras' frame rate [Hz of sim time] (default 0: "
        f"{pose_source.EYE_FPS_DEFAULT:g})",
    )
    args = p.parse_args(argv)
    if args.cameras < 0:
        p.error(f"--cameras {args.cameras}: the frame rate must be >= 0 Hz")
    if args.episodes < 1:
        p.error(f"--episodes {args.episodes}: at least 1")
    if not 0.0 <= args.v2v_loss <= 1.0:
        p.error(f"--v2v-loss {args.v2v_loss}: must be in [0, 1]")
    if args.shield_pose_error_m < 0:
        p.error(f"--shield-pose-error-m {args.shield_pose_error_m}: must be >= 0")
    if args.v2v_delay_ms < 0:
        p.error(f"--v2v-delay-ms {args.v2v_delay_ms}: must be >= 0")
    args.lcm_url = instance_lcm_url(p, args.lcm_url)
    return args


@dataclass
class CarPlan:
    vehicle: str
    route: str
    start: tasks.Pose
    goal: tuple[float, float]  # on the route [m]


def plan_episode(seed: int) -> list[CarPlan]:
    """The episode of seed as training draws them (autodrive.learn.marl.env: the one place of
    the task): each car its own approach, a turn (left, straight or right) and a spawn time,
    a later spawn starting further back on its approach; the goal on its exit lane."""
    rng = np.random.default_rng(seed)
    approaches = rng.permutation(len(marl_env.APPROACHES))[:CARS]
    plans = []
    for i, a in enumerate(approaches):
        turn = list(marl_env.TURNS)[int(rng.integers(len(marl_env.TURNS)))]
        spawn_s = float(rng.uniform(0.0, marl_env.SPAWN_SPREAD_S))
        trip = marl_env.plan_route(marl_env.route_name(marl_env.APPROACHES[int(a)], turn), spawn_s)
        plans.append(CarPlan(channels.vehicle_name(i + 1), trip.name, trip.start, trip.goal_xy_m))
    return plans


def write_runtime_config(
    path: Path, run_dir: Path, url: str, car: int, plan: CarPlan, eye: str
) -> Path:
    """The HIL runtime config of car `car` (1-based): its name and pty, SIM_CLOCK, no LIDAR,
    its EKF's map filter started by its first Eye fix, or (--eye none) at the car's marked start
    with the placement uncertainty (pose_source.estimator_start)."""
    cfg = yaml.safe_load(RUNTIME_HIL_CONFIG.read_text())
    cfg["lcm_url"] = url
    cfg["clock"] = "sim"
    cfg["vehicle"]["name"] = channels.vehicle_name(car)
    cfg["bridge"]["device"] = str(run_dir / f"nigel{car}-nano")
    cfg.pop("lidar", None)  # the sim runs --no-lidar: nothing here needs it
    pose_source.estimator_start(cfg, eye, plan.start)
    path.write_text(yaml.safe_dump(cfg, sort_keys=False))
    return path


@dataclass
class EpisodeRecord:
    truth: dict[str, list[tuple[float, float, float]]] = field(default_factory=dict)  # t, x, y
    collided: set[str] = field(default_factory=set)
    steering: dict[str, list[tuple[float, float]]] = field(default_factory=dict)  # t, steer
    at_goal: set[str] = field(default_factory=set)
    goal_t: dict[str, float] = field(default_factory=dict)  # sim time at the goal [s]
    sim_s: float = 0.0
    poses: pose_source.PoseRecord = field(default_factory=pose_source.PoseRecord)
    eye_sync_give_ups: int | None = None  # the sim gave the Eye up (pose_source; None: no lockstep)
    children: list[ChildExit] = field(default_factory=list)  # how the episode's processes ended


def ensure_keys(say: Any) -> None:
    """The cars' command keys and the testbed certificates (V2V, V2I, lights, Eye poses)."""
    v2x_ca.ensure_run_keys([channels.vehicle_name(i) for i in range(1, CARS + 1)], say)


def run_episode(
    args: argparse.Namespace,
    ep: int,
    plans: list[CarPlan],
    build: Path,
    out: Path,
    say: Any,
    stop_requested: Any,
) -> tuple[EpisodeRecord, list[dict[str, Any]], str]:
    """Runs one episode; returns what was recorded, the autodrive-marl summaries and why it
    ended ('goal', 'collision', 'timeout', 'interrupted')."""
    types = lcmtypes.load(build)
    ep_dir = out / f"episode-{ep:02d}"
    ep_dir.mkdir(parents=True, exist_ok=True)
    run_dir = Path(f"/tmp/autodrive-intersection-{os.getpid()}")
    run_dir.mkdir(parents=True, exist_ok=True)
    rec = EpisodeRecord()
    lc = lcmtypes.bus(args.lcm_url)
    fps = args.cameras or pose_source.EYE_FPS_DEFAULT
    latency = pose_source.lockstep_latency_ms(args, lockstep=True)  # the sim: --lockstep-client

    def on_truth(ch: str, data: bytes) -> None:
        m = types.ground_truth_t.decode(data)
        v = ch.split("_")[0]
        rec.truth.setdefault(v, []).append((m.utime * 1e-6, m.position_m[0], m.position_m[1]))
        rec.poses.on_truth(v, m.utime * 1e-6, m.position_m[0], m.position_m[1])
        rec.sim_s = max(rec.sim_s, m.utime * 1e-6)
        if m.in_collision:
            rec.collided.add(v)

    def on_command(ch: str, data: bytes) -> None:
        m = types.vehicle_command_t.decode(data)
        if m.engaged:
            rec.steering.setdefault(ch.split("_")[0], []).append((m.utime * 1e-6, m.steering))

    def on_mission(ch: str, data: bytes) -> None:
        m = types.mission_status_t.decode(data)
        if m.state == types.mission_status_t.PARKED and m.vehicle not in rec.at_goal:
            rec.at_goal.add(m.vehicle)
            rec.goal_t[m.vehicle] = m.utime * 1e-6

    def on_eye(_ch: str, data: bytes) -> None:
        m = types.pose2d_t.decode(data)
        rec.poses.on_eye(m.vehicle, m.utime * 1e-6)

    def on_pose_map(ch: str, data: bytes) -> None:
        m = types.odometry_t.decode(data)
        rec.poses.on_ekf(ch.split("_")[0], m.utime * 1e-6, m.x_m, m.y_m)

    subs = []
    for p in plans:
        subs.append(lc.subscribe(channels.channel("POSE_EYE", p.vehicle), on_eye))
        subs.append(lc.subscribe(channels.channel("POSE_MAP", p.vehicle), on_pose_map))
        subs.append(lc.subscribe(channels.channel("GROUND_TRUTH", p.vehicle), on_truth))
        subs.append(lc.subscribe(channels.channel("COMMAND", p.vehicle), on_command))
        subs.append(lc.subscribe(channels.channel("MISSION", p.vehicle), on_mission))
    procs = ProcessGroup(lambda m: None)
    summaries: list[dict[str, Any]] = []
    ended = "timeout"
    marl_procs = []
    try:
        sim = [build / "bin" / "autodrive-sim", "--map", MAP, "--cars", CARS]
        sim += ["--run-dir", run_dir, "--seed", args.seed * 1000 + ep, "--lcm-url", args.lcm_url]
        sim += ["--no-lidar", "--lockstep-client", "--duration", EPISODE_SIM_S + 5, "--quiet"]
        seed = args.seed * 1000 + ep
        marked = [p.start for p in plans]
        for i, (x, y, yaw) in enumerate(pose_source.placed(marked, args.eye, seed)):
            sim += ["--car-start", f"{i + 1},{x:.4f},{y:.4f},{math.degrees(yaw):.3f}"]
        sim += pose_source.sim_argv(args.eye, fps, latency, args.eye_sync_wait_s)
        if (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")) and not args.headless:
            sim += ["--view"]
        procs.start("autodrive-sim", sim, ep_dir / "sim.log")
        for i in range(CARS):
            wait_for_path(run_dir / f"nigel{i + 1}-nano", PTY_TIMEOUT_S, procs)
        names = [p.vehicle for p in plans]
        pose_source.start(
            procs, args.eye, build, MAP, ep_dir, args.lcm_url, names, seed, fps, latency
        )
        for i, p in enumerate(plans):
            cfg = write_runtime_config(
                ep_dir / f"runtime{i + 1}.yaml", run_dir, args.lcm_url, i + 1, p, args.eye
            )
            procs.start(
                f"autodrive-runtime {p.vehicle}",
                [build / "bin" / "autodrive-runtime", "--config", cfg, "--route", p.route],
                ep_dir / f"runtime{i + 1}.log",
            )
        for i, p in enumerate(plans):
            marl = [build / "bin" / "autodrive-marl", "--vehicle", p.vehicle]
            marl += ["--lcm-url", args.lcm_url, "--clock", "sim", "--map-json", MAP_JSON]
            marl += [
                "--route",
                p.route,
                "--mode",
                args.policy,
                "--goal",
                f"{p.goal[0]},{p.goal[1]}",
            ]
            marl += ["--goal-tolerance-m", marl_env.GOAL_REACHED_M]
            marl += ["--waypoint-lookahead-m", marl_env.LOOKAHEAD_M]
            marl += ["--v2v-loss", args.v2v_loss, "--v2v-delay-ms", args.v2v_delay_ms]
            marl += ["--shield-pose-error-m", args.shield_pose_error_m]
            marl += ["--seed", args.seed * 1000 + ep * 10 + i]
            if args.policy == "rl":
                marl += ["--policy", args.policy_file]
            if args.no_shield:
                marl += ["--no-shield"]
            marl_procs.append(
                procs.start(f"autodrive-marl {p.vehicle}", marl, ep_dir / f"marl{i + 1}.log")
            )
        while True:
            if stop_requested():
                ended = "interrupted"
                break
            procs.check()
            if select.select([lc.fileno()], [], [], 0.1)[0]:
                lc.handle()
            if rec.collided:
                ended = "collision"
                break
            if len(rec.at_goal) == CARS:
                ended = "goal"
                break
            if rec.sim_s > EPISODE_SIM_S:
                break
    finally:
        rec.children = procs.stop_all()
        rec.eye_sync_give_ups = pose_source.eye_sync_give_ups(ep_dir / "sim.log", latency)
        for s in subs:
            lc.unsubscribe(s)
        shutil.rmtree(run_dir, ignore_errors=True)
    for i in range(CARS):
        log = (ep_dir / f"marl{i + 1}.log").read_text(errors="replace").strip().splitlines()
        for line in reversed(log):
            if line.startswith("{"):
                summaries.append(json.loads(line))
                break
    return rec, summaries, ended


def episodes_give_ups(recs: list[EpisodeRecord]) -> int | None:
    """The episodes' sims' give-ups of the Eye in all: None when none was in lockstep, -1 when
    any count is unknown (pose_source.eye_sync_give_ups)."""
    counts = [r.eye_sync_give_ups for r in recs if r.eye_sync_give_ups is not None]
    if not counts:
        return None
    return -1 if min(counts) < 0 else sum(counts)


def goal_errors_m(plans: list[CarPlan], rec: EpisodeRecord) -> list[float]:
    """For each car its EKF put at the goal: its true distance from the goal then [m]."""
    return [e for e in true_goal_errors_m(plans, rec).values() if e is not None]


def true_goal_errors_m(plans: list[CarPlan], rec: EpisodeRecord) -> dict[str, float | None]:
    """Each car's true distance from its goal [m] at the first ground truth after its EKF said
    "at the goal"; None when it never said so (or no ground truth came after)."""
    out: dict[str, float | None] = {}
    for p in plans:
        out[p.vehicle] = None
        if p.vehicle in rec.at_goal and rec.truth.get(p.vehicle):
            t_goal = rec.goal_t.get(p.vehicle, math.inf)
            after = [(x, y) for t, x, y in rec.truth[p.vehicle] if t >= t_goal]
            if after:
                out[p.vehicle] = float(math.hypot(after[0][0] - p.goal[0], after[0][1] - p.goal[1]))
    return out


def episode_outcome(plans: list[CarPlan], rec: EpisodeRecord, ended: str) -> str:
    """How the episode ended, judged from ground truth: 'goal' only when every car's EKF said
    so and its ground truth was then within GOAL_TRUE_TOLERANCE_M of its goal ('goal_false'
    when a car only believed it); otherwise how it ended (collision, timeout)."""
    if ended != "goal":
        return ended
    errors = true_goal_errors_m(plans, rec).values()
    ok = all(e is not None and e <= GOAL_TRUE_TOLERANCE_M for e in errors)
    return "goal" if ok else "goal_false"


def score_episodes(
    requested: int, outcomes: list[str], traverse_s: list[list[float | None]]
) -> dict[str, Any]:
    """The mission's rates over every planned episode: an episode not run (a wall --timeout, an
    interruption) is a failure. outcomes: episode_outcome of each episode run; traverse_s: each
    run episode's cars' start-to-goal times [s of sim time] (None: did not arrive). The mean
    traverse time counts every car of every planned episode, one that did not arrive (or whose
    episode did not run) at the episode's whole EPISODE_SIM_S."""
    n = len(outcomes)
    successes = sum(o == "goal" for o in outcomes)
    cars = [t if t is not None else EPISODE_SIM_S for ep in traverse_s for t in ep]
    cars += [EPISODE_SIM_S] * (CARS * (requested - n))
    arrived = [t for ep in traverse_s for t in ep if t is not None]
    return {
        "episodes": n,
        "episodes_requested": requested,
        "episodes_not_run": requested - n,
        "successes": successes,
        "success_rate": round(successes / requested, 4) if requested else 0.0,
        "goal_believed_not_true": sum(o == "goal_false" for o in outcomes),
        "timeouts": sum(o == "timeout" for o in outcomes),
        "mean_traverse_s": round(float(np.mean(cars)), 3) if cars else None,
        "mean_traverse_s_arrived": round(float(np.mean(arrived)), 3) if arrived else None,
        "cars_arrived": len(arrived),
    }


def ekf_errors_m(rec: EpisodeRecord) -> list[float]:
    """Every car's EKF map pose against the ground truth at the same sim time [m]: what the
    shield works on."""
    return [e for car in sorted(rec.poses.ekf) for e in rec.poses.errors_m(car)]


def steering_rates(rec: EpisodeRecord) -> list[float]:
    """Every car's steering rate between consecutive commands [1/s of normalised steering]."""
    rates: list[float] = []
    for cmds in rec.steering.values():
        for (t0, s0), (t1, s1) in zip(cmds, cmds[1:]):
            if t1 > t0:
                rates.append((s1 - s0) / (t1 - t0))
    return rates


def plot(path: Path, episodes: list[tuple[list[CarPlan], EpisodeRecord, str]]) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    n = len(episodes)
    cols = min(5, n)
    rows = (n + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(3 * cols, 3 * rows), squeeze=False)
    colours = ("tab:blue", "tab:orange", "tab:green", "tab:red")
    for k, (plans, rec, ended) in enumerate(episodes):
        ax = axes[k // cols][k % cols]
        for r in tasks.routes(MAP):
            pts = tasks.route(MAP, r).points_m
            ax.plot(pts[:, 0], pts[:, 1], color="0.85", lw=0.6)
        for i, p in enumerate(plans):
            tr = np.array(rec.truth.get(p.vehicle, [(0.0, p.start[0], p.start[1])]))
            ax.plot(tr[:, 1], tr[:, 2], color=colours[i % 4], lw=1.2, label=p.vehicle)
            ax.plot(p.start[0], p.start[1], "o", color=colours[i % 4], ms=3)
            if p.vehicle in rec.collided:
                ax.plot(tr[-1, 1], tr[-1, 2], "kx", ms=8)
        ax.set_title(f"episode {k}: {ended}", fontsize=8)
        ax.set_xlim(-PLOT_HALF_M, PLOT_HALF_M)
        ax.set_ylim(-PLOT_HALF_M, PLOT_HALF_M)
        ax.set_aspect("equal")
        ax.tick_params(labelsize=6)
    for k in range(n, rows * cols):
        axes[k // cols][k % cols].axis("off")
    axes[0][0].legend(fontsize=6, loc="lower left")
    fig.suptitle("Intersection School HIL: ground-truth trajectories [m] (x: collision)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def run(args: argparse.Namespace) -> int:
    build, out = Path(args.build), Path(args.out)
    out.mkdir(parents=True, exist_ok=True)

    def say(msg: str) -> None:
        print(f"[demo intersection] {msg}", flush=True)

    for prog in ("autodrive-sim", "autodrive-runtime", "autodrive-marl"):
        if not (build / "bin" / prog).exists():
            say(f"ERROR: {build / 'bin' / prog} is missing: build first (tools/demo does)")
            return 2
    if args.policy == "rl":
        pf = Path(args.policy_file)
        if not pf.is_file() or not pf.with_suffix(".json").is_file():
            say(f"ERROR: --policy-file {pf}: needs {pf.name} and {pf.with_suffix('.json').name}")
            return 2
    ensure_keys(say)
    interrupted = False

    def on_signal(_sig: int, _frame: FrameType | None) -> None:
        nonlocal interrupted
        interrupted = True

    old = [(s, signal.signal(s, on_signal)) for s in (signal.SIGINT, signal.SIGTERM)]
    t0 = time.time()
    done: list[tuple[list[CarPlan], EpisodeRecord, str]] = []
    summaries_all: list[dict[str, Any]] = []
    traverse_s: list[list[float | None]] = []  # per episode run, per car [s] (None: not arrived)
    outcomes: list[str] = []
    rates: list[float] = []
    goal_err: list[float] = []
    ekf_err: list[float] = []
    try:
        for ep in range(args.episodes):
            if interrupted or time.time() - t0 > args.timeout:
                break
            plans = plan_episode(args.seed * 1000 + ep)
            routes = ", ".join(f"{p.vehicle} {p.route}" for p in plans)
            say(f"episode {ep + 1}/{args.episodes}: {routes}")
            rec, summaries, ended = run_episode(
                args, ep, plans, build, out, say, lambda: interrupted
            )
            if ended == "interrupted":
                break
            ended = episode_outcome(plans, rec, ended)
            done.append((plans, rec, ended))
            outcomes.append(ended)
            summaries_all += summaries
            arrived = [
                s["goal_s"] - s["start_s"]
                for s in summaries
                if s.get("goal_s", -1) >= 0 and s.get("start_s", -1) >= 0
            ]
            traverse_s.append([*arrived, *[None] * (CARS - len(arrived))])
            rates += steering_rates(rec)
            goal_err += goal_errors_m(plans, rec)
            errs = ekf_errors_m(rec)
            ekf_err += errs
            ekf_max = max(errs, default=math.nan)
            shield = sum(s.get("shield_interventions", 0) for s in summaries)
            say(
                f"episode {ep + 1}: {ended} ({len(rec.at_goal)}/{CARS} at goal, "
                f"{len(rec.collided)} collided, {shield} shield interventions, EKF error max "
                f"{ekf_max:.3f} m, "
                f"{rec.sim_s:.1f} s sim, {time.time() - t0:.0f} s wall so far)"
            )
    finally:
        for sig, handler in old:
            signal.signal(sig, handler)
    if len(done) < args.episodes and not interrupted:
        say(f"ERROR: --timeout {args.timeout:g} s of wall time ran out after {len(done)} of "
            f"{args.episodes} episodes: the {args.episodes - len(done)} not run count as failures")  # fmt: skip
    lat = pose_source.lockstep_latency_ms(args, lockstep=True)
    rep: dict[str, Any] = {
        "mission": "intersection",
        "policy": args.policy,
        "policy_file": args.policy_file if args.policy == "rl" else None,
        "shield": not args.no_shield,
        "seed": args.seed,
        "v2v_loss": args.v2v_loss,
        "v2v_delay_ms": args.v2v_delay_ms,
        "shield_pose_error_m": args.shield_pose_error_m,
        **pose_source.report(
            args.eye,
            pose_source.describe(args.eye, MAP, args.cameras or pose_source.EYE_FPS_DEFAULT, lat),
            [r.poses for _p, r, _e in done],
            [channels.vehicle_name(i + 1) for i in range(CARS)],
            lat,
            episodes_give_ups([r for _p, r, _e in done]),
        ),
        "eye_poses": sum(sum(r.poses.eye_poses.values()) for _p, r, _e in done),
        **score_episodes(args.episodes, outcomes, traverse_s),
        "collisions": sum(1 for _p, r, _e in done if r.collided),
        "shield_interventions": sum(s.get("shield_interventions", 0) for s in summaries_all),
        # of them, steps where the shield's lane term replaced the policy's steering
        "shield_lane_steers": sum(s.get("shield_lane_steers", 0) for s in summaries_all),
        "steering_rate_rms": round(float(np.sqrt(np.mean(np.square(rates)))), 4) if rates else None,
        "goal_error_true_max_m": (
            round(max(goal_err), 3) if goal_err else None
        ),  # how far from its goal a car really was when its EKF said it was there
        "goal_true_tolerance_m": GOAL_TRUE_TOLERANCE_M,
        # every EKF map pose against the truth then [m] (the shield's input)
        "ekf_error_true_p95_m": round(float(np.percentile(ekf_err, 95)), 4) if ekf_err else None,
        "ekf_error_true_max_m": round(max(ekf_err), 4) if ekf_err else None,
        "v2v_lost": sum(s.get("v2v_lost", 0) for s in summaries_all),
        "v2v_dropped_stale": sum(s.get("v2v_dropped_stale", 0) for s in summaries_all),
        "per_episode": [
            {
                "ended": e,
                "routes": [p.route for p in plans],
                "at_goal": sorted(r.at_goal),
                "collided": sorted(r.collided),
                "sim_s": round(r.sim_s, 2),
                "eye_sync_give_ups": r.eye_sync_give_ups,
            }
            for plans, r, e in done
        ],
        "wall_s": round(time.time() - t0, 1),
        "interrupted": interrupted,
    }
    record_children(rep, [c for _p, r, _e in done for c in r.children], say)
    rep["ok"] = exit_code(rep) == 0
    pose_source.eye_sync_verdict(rep, runs=len(done), say=say)  # it depended on wall time: fails
    (out / "report.json").write_text(json.dumps(rep, indent=2))
    if done:
        plot(out / "trajectories.png", done)
    say(f"report: {json.dumps({k: v for k, v in rep.items() if k != 'per_episode'})}")
    say(pose_source.summary_line(rep))
    say(f"wrote {out / 'report.json'} and {out / 'trajectories.png'}")
    if interrupted:
        say("interrupted: every process stopped")
        return EXIT_INTERRUPTED
    return exit_code(rep)


def exit_code(rep: dict[str, Any]) -> int:
    """The mission's verdict on its report: 0 only when every planned episode succeeded (one a
    wall --timeout left unrun is a failure), no car collided and no process left a sanitizer
    report; else 1."""
    ok = rep["success_rate"] == 1.0 and rep["collisions"] == 0 and not rep["sanitizer_reports"]
    return 0 if ok and rep.get("ok", True) else 1  # "ok" false: e.g. the Eye fell behind


def main(argv: list[str] | None = None) -> int:
    return run(parse_args(argv))


if __name__ == "__main__":
    sys.exit(main())
