"""Autonomous parking mission for tools/demo: runs autodrive-autonomy (mapping, saving,
localising, Hybrid A* planning, pure-pursuit driving) on the runtime's LIDAR and EKF odometry,
then scores the run against the simulator's ground truth.

Frames: the autonomy works in the frame of the car's start pose (its SLAM origin); the
simulator's world frame is the map's. The start pose is the map's `spawn` site."""
import math
import pathlib
import re
import subprocess
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent
# Parking School slots (sim/mujoco_hil/tools/gen_maps.py): 0.3 m wide, lines at x = -1.2 +
# 0.3 k, centre line y = 1.25 [m]. Forward-in: the rear axle (base_link) sits 0.07 m behind
# the slot centre, so the car body (centre 0.0708 m ahead of the axle) is centred in it.
SLOT_X0_M, SLOT_PITCH_M, SLOT_Y_M, SLOTS = -1.05, 0.30, 1.25, 6
CENTRE_AHEAD_M = 0.0708


def spawn_pose(map_xml):
    m = re.search(
        r'<site name="spawn" pos="([-\d.]+) ([-\d.]+) [-\d.]+" euler="[-\d.]+ [-\d.]+ ([-\d.]+)"',
        pathlib.Path(map_xml).read_text(),
    )
    if not m:
        raise RuntimeError(f'{map_xml}: no <site name="spawn" pos=.. euler=..>')
    return float(m.group(1)), float(m.group(2)), math.radians(float(m.group(3)))


def parse_pose_deg(text):
    """ "X,Y,YAW_DEG" as (x, y, yaw_rad) [m, m, rad]; ValueError saying what is wrong."""
    parts = text.split(",")
    if len(parts) != 3:
        raise ValueError("expected X,Y,YAW_DEG, e.g. -1.0,0.6,0")
    try:
        x, y, yaw_deg = (float(v) for v in parts)
    except ValueError:
        raise ValueError("X, Y and YAW_DEG must be numbers") from None
    if not all(map(math.isfinite, (x, y, yaw_deg))):
        raise ValueError("X, Y and YAW_DEG must be finite")
    return x, y, math.radians(yaw_deg)


def start_pose(text, seed):
    """World start pose [m, m, rad]: --start X,Y,YAW_DEG, or the spawn moved by the seed."""
    if text:
        return parse_pose_deg(text)
    x, y, yaw = spawn_pose(ROOT / "sim/mujoco_hil/maps/parking_school.xml")
    if seed == 0:
        return x, y, yaw
    import random

    rng = random.Random(seed)  # the same seed, the same scenario
    return (
        x + rng.uniform(-0.05, 0.05),
        y + rng.uniform(-0.05, 0.05),
        yaw + math.radians(rng.uniform(-5.0, 5.0)),
    )


def slot_goal_world(slot):
    if not 0 <= slot < SLOTS:
        raise RuntimeError(f"--slot {slot}: Parking School has slots 0..{SLOTS - 1}")
    return SLOT_X0_M + SLOT_PITCH_M * slot, SLOT_Y_M - CENTRE_AHEAD_M, math.pi / 2


def to_frame(origin, p):
    """World pose p expressed in the frame whose pose in the world is origin."""
    dx, dy = p[0] - origin[0], p[1] - origin[1]
    c, s = math.cos(origin[2]), math.sin(origin[2])
    return c * dx + s * dy, -s * dx + c * dy, _wrap(p[2] - origin[2])


def to_world(origin, p):
    c, s = math.cos(origin[2]), math.sin(origin[2])
    return origin[0] + c * p[0] - s * p[1], origin[1] + s * p[0] + c * p[1], _wrap(p[2] + origin[2])


def _wrap(a):
    return (a + math.pi) % (2 * math.pi) - math.pi


def mapping_route(text):
    """--mapping-route X,Y,YAW_DEG[;...] (start frame) as [(x, y, yaw_rad)]; '' = none."""
    route = []
    for leg in filter(None, (t.strip() for t in text.split(";"))):
        try:
            route.append(parse_pose_deg(leg))
        except ValueError as e:
            raise ValueError(f"--mapping-route leg '{leg}': {e}") from None
    return route


def write_config(example, out_dir, url, goal_local, seed, route=()):
    import yaml

    cfg = yaml.safe_load(pathlib.Path(example).read_text())
    cfg["lcm_url"] = url
    cfg["out_dir"] = str(out_dir / "autonomy")
    cfg["map"]["save_to"] = str(out_dir / "map.yaml")
    cfg["map"]["load_from"] = ""
    cfg["goal"] = {"x_m": goal_local[0], "y_m": goal_local[1], "yaw_rad": goal_local[2]}
    cfg["amcl"]["seed"] = seed
    cfg["mapping_route"] = [{"x_m": x, "y_m": y, "yaw_rad": yaw} for x, y, yaw in route]
    path = out_dir / "autonomy.yaml"
    path.write_text(yaml.safe_dump(cfg, sort_keys=False))
    return path


def late_boxes(specs):
    """--late-box X,Y,T[,SX,SY] values as (x, y, t, half_x, half_y) [m, m, s, m, m]; the
    simulator validates them and exits 2 on a bad one."""
    out = []
    for spec in specs:
        v = [float(f) for f in spec.split(",")]
        out.append((v[0], v[1], v[2], v[3] if len(v) > 3 else 0.06, v[4] if len(v) > 4 else 0.06))
    return out


def run(
    build, out_dir, url, slot, seed, start, timeout_s, procs, stop_requested, boxes=(), route=()
):
    goal_w = slot_goal_world(slot)
    goal_l = to_frame(start, goal_w)
    cfg = write_config(
        ROOT / "runtime/jetson/autonomy/config/autonomy.example.yaml",
        out_dir,
        url,
        goal_l,
        seed,
        route,
    )
    print(
        f"[demo] start at world ({start[0]:.3f}, {start[1]:.3f}, {math.degrees(start[2]):.1f} deg)",
        flush=True,
    )
    print(
        f"[demo] mission: park in slot {slot} at world ({goal_w[0]:.3f}, {goal_w[1]:.3f}, "
        f"{math.degrees(goal_w[2]):.0f} deg)",
        flush=True,
    )
    proc = procs.start(
        "autodrive-autonomy",
        [build / "bin" / "autodrive-autonomy", "--config", cfg],
        out_dir / "autonomy.log",
    )
    t0 = time.time()
    seen = 0
    while proc.poll() is None:
        if stop_requested():
            break
        if time.time() - t0 > timeout_s:
            raise RuntimeError(f"the mission did not finish within {timeout_s:.0f} s wall")
        for name, p, _ in procs.items:
            if name != "autodrive-autonomy" and p.poll() is not None:
                raise RuntimeError(f"{name} exited with code {p.returncode}")
        lines = (out_dir / "autonomy.log").read_text().splitlines()
        for ln in lines[seen:]:
            print(ln, flush=True)  # the mission's state changes, as they happen
        seen = len(lines)
        time.sleep(0.2)
    for ln in (out_dir / "autonomy.log").read_text().splitlines()[seen:]:
        print(ln, flush=True)
    return {
        "mission_exit_code": proc.returncode,
        "slot": slot,
        "start_world": list(start),
        "goal_world": list(goal_w),
        "late_boxes_world": [list(b) for b in boxes],
    }


def score(log_path, out_dir, veh, mission):
    """Parking figures against ground truth; writes gt.csv (in the autonomy frame) and plots."""
    import lcm
    from autodrive import ground_truth_t, odometry_t, pose2d_t

    start, goal_w = mission["start_world"], mission["goal_world"]
    gt, gt_t, amcl = [], [], []
    odom = {"laser_odom": [], "ekf_odom": []}
    for ev in lcm.EventLog(str(log_path), "r"):
        if ev.channel == f"{veh}_GROUND_TRUTH":
            m = ground_truth_t.decode(ev.data)
            gt.append((m.position_m[0], m.position_m[1], m.yaw_rad))
            gt_t.append(m.utime)
        elif ev.channel == f"{veh}_POSE_AMCL":
            m = pose2d_t.decode(ev.data)
            amcl.append((m.utime, m.x_m, m.y_m, m.yaw_rad))
        elif ev.channel in (f"{veh}_LASER_ODOM", f"{veh}_ODOM"):
            m = odometry_t.decode(ev.data)
            odom["laser_odom" if ev.channel.endswith("LASER_ODOM") else "ekf_odom"].append(
                (m.utime, m.x_m, m.y_m, m.yaw_rad)
            )
    rep = {}
    if not gt:
        return {"error": "no ground truth in the log"}
    final = gt[-1]
    rep["success"] = mission.get("mission_exit_code") == 0
    rep["final_pos_error_m"] = round(math.hypot(final[0] - goal_w[0], final[1] - goal_w[1]), 4)
    rep["final_heading_error_deg"] = round(abs(math.degrees(_wrap(final[2] - goal_w[2]))), 3)
    boxes = mission.get("late_boxes_world", [])
    rep["min_clearance_m"] = round(
        min_clearance(gt, extra=[(b[0], b[1], b[3], b[4], 0.0) for b in boxes]), 4
    )
    # Each estimate against the truth at its own stamp (the scan's mid-time; both are sim time
    # [us], the runtime runs on SIM_CLOCK), not at its arrival: the arrival lags by the scan.
    import bisect

    errs = []
    for t, x, y, yaw in amcl:
        i = min(bisect.bisect_left(gt_t, t), len(gt) - 1)
        w = to_world(start, (x, y, yaw))
        errs.append(math.hypot(w[0] - gt[i][0], w[1] - gt[i][1]))
    rep["localization_rms_m"] = (
        round(math.sqrt(sum(e * e for e in errs) / len(errs)), 4) if errs else None
    )
    # Dead reckoning, laser (ICP) against wheel/IMU (EKF), over the same span of the run.
    span = (odom["laser_odom"][0][0], odom["laser_odom"][-1][0]) if odom["laser_odom"] else None
    tracks = {}
    for name, samples in odom.items():
        tr = aligned_track(samples, gt_t, gt, span)
        if tr:
            tracks[name] = tr
            rep[f"{name}_final_error_m"], rep[f"{name}_drift_pct"] = odometry_drift(tr, gt_t, gt)
    if tracks:
        err = plot_odometry(tracks, gt, gt_t, span, rep, out_dir / "odometry.png")
        if err:
            rep["plot_error"] = err
    with open(out_dir / "gt.csv", "w") as f:
        f.write("x_m,y_m,yaw_rad\n")
        for g in gt[::10]:
            p = to_frame(start, g)
            f.write(f"{p[0]:.5f},{p[1]:.5f},{p[2]:.5f}\n")
    auto = out_dir / "autonomy"
    goal_l = to_frame(start, goal_w)
    argv = [
        str(ROOT / "tools/plot-parking"),
        "--map",
        str(out_dir / "map.yaml"),
        "--truth",
        str(out_dir / "gt.csv"),
        "--goal",
        ",".join(f"{v:.4f}" for v in goal_l),
        "--out",
        str(out_dir / "parking.png"),
    ]
    for b in boxes:
        p = to_frame(start, (b[0], b[1], 0.0))
        argv += ["--box", f"{p[0]:.4f},{p[1]:.4f},{p[2]:.4f},{b[3]:.4f},{b[4]:.4f}"]
    for name in ("path", "route", "trajectory"):
        if (auto / f"{name}.csv").exists():
            argv += [f"--{name}", str(auto / f"{name}.csv")]
    if (out_dir / "map.yaml").exists():
        r = subprocess.run(argv, capture_output=True, text=True)
        if r.returncode != 0:
            rep["plot_error"] = r.stderr.strip()[-300:]
    return rep


def aligned_track(samples, gt_t, gt, span):
    """An odometry track [(t_us, x, y)] in the world, aligned with the truth at its first
    sample inside span (sim-time stamps [us]): dead reckoning from a known start. None if
    fewer than two samples."""
    import bisect

    if not span:
        return None
    samples = [s for s in samples if span[0] <= s[0] <= span[1]]
    if len(samples) < 2:
        return None
    t0, x0, y0, yaw0 = samples[0]
    g0 = gt[min(bisect.bisect_left(gt_t, t0), len(gt) - 1)]
    dyaw = _wrap(g0[2] - yaw0)
    c, s = math.cos(dyaw), math.sin(dyaw)
    return [
        (t, g0[0] + c * (x - x0) - s * (y - y0), g0[1] + s * (x - x0) + c * (y - y0))
        for t, x, y, _ in samples
    ]


def odometry_drift(track, gt_t, gt):
    """(final position error [m], as % of the distance driven) of an aligned track."""
    import bisect

    i0 = bisect.bisect_left(gt_t, track[0][0])
    i1 = min(bisect.bisect_left(gt_t, track[-1][0]), len(gt) - 1)
    err = math.hypot(track[-1][1] - gt[i1][0], track[-1][2] - gt[i1][1])
    dist = sum(math.hypot(b[0] - a[0], b[1] - a[1]) for a, b in zip(gt[i0:i1], gt[i0 + 1 : i1 + 1]))
    return round(err, 4), round(100.0 * err / dist, 2) if dist > 0.05 else None


def plot_odometry(tracks, gt, gt_t, span, rep, path):
    """odometry.png: laser and EKF dead reckoning against the truth over the same span."""
    import bisect

    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as e:
        return str(e)
    i0, i1 = bisect.bisect_left(gt_t, span[0]), bisect.bisect_left(gt_t, span[1])
    fig, ax = plt.subplots(figsize=(7, 6))
    ax.plot([g[0] for g in gt[i0:i1]], [g[1] for g in gt[i0:i1]], "k-", lw=2, label="ground truth")
    style = {
        "laser_odom": ("tab:blue", "laser odometry (ICP)"),
        "ekf_odom": ("tab:red", "EKF odometry (wheels + IMU)"),
    }
    for name, tr in tracks.items():
        colour, label = style[name]
        pct = rep.get(f"{name}_drift_pct")
        ax.plot(
            [p[1] for p in tr],
            [p[2] for p in tr],
            "--",
            color=colour,
            lw=1.2,
            label=f"{label}: {pct} % drift" if pct is not None else label,
        )
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title("dead reckoning from the same start, world frame")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return None


def _obstacles():
    """Collidable boxes and cones of Parking School as (centre, half sizes, yaw) rectangles."""
    text = (ROOT / "sim/mujoco_hil/maps/parking_school.xml").read_text()
    obs = []
    for m in re.finditer(
        r'<geom name="box_\w+" type="box" pos="([-\d. ]+)" size="([-\d. ]+)" '
        r'euler="[-\d.]+ [-\d.]+ ([-\d.]+)"',
        text,
    ):
        p = [float(v) for v in m.group(1).split()]
        s = [float(v) for v in m.group(2).split()]
        obs.append((p[0], p[1], s[0], s[1], float(m.group(3))))
    for m in re.finditer(r'<body name="cone_\d+" pos="([-\d. ]+)"', text):
        p = [float(v) for v in m.group(1).split()]
        obs.append((p[0], p[1], 0.025, 0.025, 0.0))
    return obs


def _corners(cx, cy, hx, hy, yaw):
    c, s = math.cos(yaw), math.sin(yaw)
    return [
        (cx + c * dx - s * dy, cy + s * dx + c * dy)
        for dx, dy in ((hx, hy), (-hx, hy), (-hx, -hy), (hx, -hy))
    ]


def _seg_dist(p, a, b):
    ax, ay = b[0] - a[0], b[1] - a[1]
    t = max(0.0, min(1.0, ((p[0] - a[0]) * ax + (p[1] - a[1]) * ay) / (ax * ax + ay * ay)))
    return math.hypot(a[0] + t * ax - p[0], a[1] + t * ay - p[1])


def _poly_dist(pa, pb):
    d = float("inf")
    for P, Q in ((pa, pb), (pb, pa)):
        for p in P:
            for i in range(4):
                d = min(d, _seg_dist(p, Q[i], Q[(i + 1) % 4]))
    return d  # overlapping rectangles are caught by the collision flag instead


def min_clearance(gt, length_m=0.24, width_m=0.178, centre_ahead_m=0.07, extra=()):
    """Smallest gap [m] between the car's envelope (chassis box and wheels) and any obstacle over
    the run (the map's and the extra (x, y, half_x, half_y, yaw) boxes; a late box counts all
    run long)."""
    obs = [_corners(*o) for o in list(_obstacles()) + list(extra)]
    best = float("inf")
    for x, y, yaw in gt[::10]:
        car = _corners(
            x + centre_ahead_m * math.cos(yaw),
            y + centre_ahead_m * math.sin(yaw),
            length_m / 2,
            width_m / 2,
            yaw,
        )
        for o in obs:
            best = min(best, _poly_dist(car, o))
    return best
