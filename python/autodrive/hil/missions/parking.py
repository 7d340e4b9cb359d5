"""The parking mission: runs autodrive-autonomy (mapping, saving, localising, Hybrid A*
planning, pure-pursuit driving) on the runtime's LIDAR and EKF odometry, then scores the run
against the simulator's ground truth.

Frames: the autonomy works in the frame of the car's start pose (its SLAM origin); the
simulator's world frame is the map's. The default start pose is the map's spawn."""

from __future__ import annotations

import bisect
import math
import random
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from autodrive.core import lcmtypes, plots, vehicle
from autodrive.hil import plot_parking, scoring
from autodrive.core.channels import channel
from autodrive.core.geometry import Pose, Rect, parse_pose_deg, to_frame
from autodrive.maps.facts import parking_school
from autodrive.core.settings import AUTONOMY_EXAMPLE_CONFIG
from autodrive.hil.missions import MissionContext

# The start pose drawn from a seed: the spawn moved by up to this much.
START_JITTER_M = 0.05
START_JITTER_DEG = 5.0
# A late box's half sizes when --late-box gives none [m].
LATE_BOX_HALF_M = 0.06
POLL_S = 0.2  # how often the autonomy's log is echoed
GT_CSV_STRIDE = 10  # every n-th ground-truth sample into gt.csv


@dataclass(frozen=True)
class LateBox:
    """A box the map does not have: world centre [m], appearance time [s], half sizes [m]."""

    x_m: float
    y_m: float
    t_s: float
    half_x_m: float
    half_y_m: float

    def rect(self) -> Rect:
        return (self.x_m, self.y_m, self.half_x_m, self.half_y_m, 0.0)


@dataclass
class ParkingPlan:
    slot: int
    seed: int
    start: Pose  # world [m, m, rad]
    timeout_s: float  # wall
    boxes: list[LateBox] = field(default_factory=list)
    route: list[Pose] = field(default_factory=list)  # start frame


def start_pose(text: str | None, seed: int) -> Pose:
    """World start pose [m, m, rad]: --start X,Y,YAW_DEG, or the spawn moved by the seed."""
    if text:
        return parse_pose_deg(text)
    x, y, yaw = parking_school().spawn
    if seed == 0:
        return x, y, yaw
    rng = random.Random(seed)  # the same seed, the same scenario
    return (
        x + rng.uniform(-START_JITTER_M, START_JITTER_M),
        y + rng.uniform(-START_JITTER_M, START_JITTER_M),
        yaw + math.radians(rng.uniform(-START_JITTER_DEG, START_JITTER_DEG)),
    )


def slot_goal_world(slot: int) -> Pose:
    """The rear-axle pose that centres the car's envelope in the slot, forward-in."""
    lot = parking_school()
    if not 0 <= slot < lot.slots:
        raise RuntimeError(f"--slot {slot}: Parking School has slots 0..{lot.slots - 1}")
    return lot.slot_goals[slot]


def mapping_route(text: str) -> list[Pose]:
    """--mapping-route X,Y,YAW_DEG[;...] (start frame) as [(x, y, yaw_rad)]; '' = none."""
    route = []
    for leg in filter(None, (t.strip() for t in text.split(";"))):
        try:
            route.append(parse_pose_deg(leg))
        except ValueError as e:
            raise ValueError(f"--mapping-route leg '{leg}': {e}") from None
    return route


def late_boxes(specs: Sequence[str]) -> list[LateBox]:
    """--late-box X,Y,T[,SX,SY[,R]] values; the simulator validates them and exits 2 on a bad
    one."""
    out = []
    for spec in specs:
        v = [float(f) for f in spec.split(",")]
        out.append(
            LateBox(
                v[0],
                v[1],
                v[2],
                v[3] if len(v) > 3 else LATE_BOX_HALF_M,
                v[4] if len(v) > 4 else LATE_BOX_HALF_M,
            )
        )
    return out


def write_config(out_dir: Path, url: str, goal_local: Pose, plan: ParkingPlan) -> Path:
    cfg = yaml.safe_load(AUTONOMY_EXAMPLE_CONFIG.read_text())
    cfg["lcm_url"] = url
    cfg["out_dir"] = str(out_dir / "autonomy")
    cfg["map"]["save_to"] = str(out_dir / "map.yaml")
    cfg["map"]["load_from"] = ""
    cfg["goal"] = {"x_m": goal_local[0], "y_m": goal_local[1], "yaw_rad": goal_local[2]}
    cfg["amcl"]["seed"] = plan.seed
    cfg["mapping_route"] = [{"x_m": x, "y_m": y, "yaw_rad": yaw} for x, y, yaw in plan.route]
    path = out_dir / "autonomy.yaml"
    path.write_text(yaml.safe_dump(cfg, sort_keys=False))
    return path


def run(ctx: MissionContext, plan: ParkingPlan) -> dict[str, Any]:
    start = plan.start
    goal_w = slot_goal_world(plan.slot)
    cfg = write_config(ctx.out, ctx.lcm_url, to_frame(start, goal_w), plan)
    ctx.say(f"start at world ({start[0]:.3f}, {start[1]:.3f}, {math.degrees(start[2]):.1f} deg)")
    ctx.say(
        f"mission: park in slot {plan.slot} at world ({goal_w[0]:.3f}, {goal_w[1]:.3f}, "
        f"{math.degrees(goal_w[2]):.0f} deg)"
    )
    name = "autodrive-autonomy"
    autonomy_log = ctx.out / "autonomy.log"
    proc = ctx.procs.start(name, [ctx.build / "bin" / name, "--config", cfg], autonomy_log)
    t0 = time.time()
    seen = 0

    def echo() -> None:  # the mission's state changes, as they happen
        nonlocal seen
        lines = autonomy_log.read_text().splitlines()
        for ln in lines[seen:]:
            ctx.echo(ln)
        seen = len(lines)

    while proc.poll() is None:
        if ctx.stop_requested():
            break
        if time.time() - t0 > plan.timeout_s:
            raise RuntimeError(f"the mission did not finish within {plan.timeout_s:.0f} s wall")
        ctx.procs.check(besides=name, clean_exit_fails=True)
        echo()
        time.sleep(POLL_S)
    echo()
    return {
        "mission_exit_code": proc.returncode,
        "slot": plan.slot,
        "start_world": list(start),
        "goal_world": list(goal_w),
        "late_boxes_world": [[b.x_m, b.y_m, b.t_s, b.half_x_m, b.half_y_m] for b in plan.boxes],
    }


@dataclass
class Recording:
    """What the parking score reads from the LCM log."""

    gt: list[Pose] = field(default_factory=list)  # world
    gt_t: list[int] = field(default_factory=list)  # sim time [us]
    amcl: list[scoring.Stamped] = field(default_factory=list)  # start frame
    odom: dict[str, list[scoring.Stamped]] = field(
        default_factory=lambda: {"laser_odom": [], "ekf_odom": []}
    )


def read_recording(log_path: Path, veh: str, build: Path) -> Recording:
    types = lcmtypes.load(build)
    ch_truth, ch_amcl, ch_laser, ch_odom = (
        channel(c, veh) for c in ("GROUND_TRUTH", "POSE_AMCL", "LASER_ODOM", "ODOM")
    )
    rec = Recording()
    for ev in lcmtypes.events(log_path):
        if ev.channel == ch_truth:
            m = types.ground_truth_t.decode(ev.data)
            rec.gt.append((m.position_m[0], m.position_m[1], m.yaw_rad))
            rec.gt_t.append(m.utime)
        elif ev.channel == ch_amcl:
            m = types.pose2d_t.decode(ev.data)
            rec.amcl.append((m.utime, m.x_m, m.y_m, m.yaw_rad))
        elif ev.channel in (ch_laser, ch_odom):
            m = types.odometry_t.decode(ev.data)
            key = "laser_odom" if ev.channel == ch_laser else "ekf_odom"
            rec.odom[key].append((m.utime, m.x_m, m.y_m, m.yaw_rad))
    return rec


def _odometry_figures(rec: Recording, rep: dict[str, Any], out_dir: Path) -> None:
    """Dead reckoning, laser (ICP) against wheel/IMU (EKF), over the same span of the run."""
    laser = rec.odom["laser_odom"]
    span = (laser[0][0], laser[-1][0]) if laser else None
    tracks: dict[str, plots.XY] = {}
    drift: dict[str, float | None] = {}
    for name, samples in rec.odom.items():
        tr = scoring.aligned_track(samples, rec.gt_t, rec.gt, span)
        if tr:
            tracks[name] = ([p[1] for p in tr], [p[2] for p in tr])
            rep[f"{name}_final_error_m"], drift[name] = scoring.odometry_drift(tr, rec.gt_t, rec.gt)
            rep[f"{name}_drift_pct"] = drift[name]
    if tracks and span:
        i0, i1 = bisect.bisect_left(rec.gt_t, span[0]), bisect.bisect_left(rec.gt_t, span[1])
        truth = ([g[0] for g in rec.gt[i0:i1]], [g[1] for g in rec.gt[i0:i1]])
        plots.odometry(out_dir / "odometry.png", truth, tracks, drift)


def _in_frame(origin: Sequence[float], box: Rect) -> Rect:
    x, y, yaw = to_frame(origin, (box[0], box[1], box[4]))
    return (x, y, box[2], box[3], yaw)


def score(
    log_path: Path, out_dir: Path, veh: str, build: Path, mission: dict[str, Any]
) -> dict[str, Any]:
    """Parking figures against ground truth; writes gt.csv (in the autonomy frame),
    odometry.png and parking.png."""
    start, goal_w = mission["start_world"], mission["goal_world"]
    rec = read_recording(log_path, veh, build)
    if not rec.gt:
        return {"error": "no ground truth in the log"}
    rep: dict[str, Any] = {"success": mission.get("mission_exit_code") == 0}
    pos_m, heading_deg = scoring.final_errors(rec.gt[-1], goal_w)
    rep["final_pos_error_m"] = round(pos_m, 4)
    rep["final_heading_error_deg"] = round(heading_deg, 3)
    boxes = [(b[0], b[1], b[3], b[4], 0.0) for b in mission.get("late_boxes_world", [])]
    obstacles = list(parking_school().obstacles) + boxes
    rep["min_clearance_m"] = round(scoring.min_clearance(rec.gt, vehicle.load(), obstacles), 4)
    errs = scoring.localisation_errors(rec.amcl, rec.gt_t, rec.gt, start)
    rep["localization_rms_m"] = round(scoring.rms(errs), 4) if errs else None
    _odometry_figures(rec, rep, out_dir)
    with open(out_dir / "gt.csv", "w") as f:
        f.write("x_m,y_m,yaw_rad\n")
        for g in rec.gt[::GT_CSV_STRIDE]:
            p = to_frame(start, g)
            f.write(f"{p[0]:.5f},{p[1]:.5f},{p[2]:.5f}\n")
    auto = out_dir / "autonomy"
    if (out_dir / "map.yaml").exists():

        def found(name: str) -> Path | None:
            return auto / name if (auto / name).exists() else None

        run = plot_parking.ParkingRun(
            map_yaml=out_dir / "map.yaml",
            out=out_dir / "parking.png",
            path_csv=found("path.csv"),
            route_csv=found("route.csv"),
            trajectory_csv=found("trajectory.csv"),
            truth_csv=out_dir / "gt.csv",
            goal=to_frame(start, goal_w),
            boxes=[_in_frame(start, b) for b in boxes],
        )
        try:
            plot_parking.draw(run)
        except ValueError as e:
            rep["plot_error"] = str(e)[-300:]
    return rep
