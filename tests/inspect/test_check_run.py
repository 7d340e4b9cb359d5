"""tools/check-run on a log written here with planted events (the generated LCM types, one car):
ground truth drives 1 m straight along +x from (2, 1) at yaw 0 and touches an obstacle twice;
the lease goes to teleop, lapses and comes back; the Nano reports fault bit 3 and failsafe; the
EKF's POSE_MAP and ODOM start at (0, 0, 0), their own start frame (no Eye fix). The report must
find the distance, both collisions, the holders in order, the fault, and move POSE_MAP into the
map frame onto ground truth; every channel's rate; a PNG. Then the channel audit per kind of run:
the teleop channels are all a teleop run needs (a full-run audit would list the missing cameras,
the Eye and SIM_CLOCK), and a teleop run without STATE is caught. Also tools/export-mcap's
optional output (the log's path with .mcap)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import lcm

from autodrive.core import channels, lcmtypes
from autodrive.devtools.inspect import channel_audit, check_run

VEH = "NIGEL1"
HZ = 50  # messages per second of each planted stream


def write_log(path: Path, build: Path, with_state: bool = True) -> None:
    t = lcmtypes.load(build)
    log = lcm.EventLog(str(path), "w", overwrite=True)

    def put(cid: str, utime: int, m: object) -> None:
        ch = channels.load().by_id(cid)
        log.write_event(utime, ch.resolve(VEH if ch.per_vehicle else None), m.encode())  # type: ignore[attr-defined]

    n = 2 * HZ  # 2 s, 1 m at 0.5 m/s
    for i in range(n + 1):
        u = 1_000_000 + i * 1_000_000 // HZ
        x = 0.5 * i / HZ
        g = t.ground_truth_t()
        g.utime, g.vehicle, g.position_m, g.yaw_rad = u, VEH, [2.0 + x, 1.0, 0.0], 0.0
        g.orientation_wxyz = [1.0, 0.0, 0.0, 0.0]
        g.in_collision = 20 <= i < 30 or 60 <= i < 65  # two contacts: 0.2 s and 0.1 s
        put("GROUND_TRUTH", u, g)
        for cid in ("POSE_MAP", "ODOM"):
            o = t.odometry_t()
            o.utime, o.vehicle, o.x_m, o.y_m, o.yaw_rad = u, VEH, x, 0.0, 0.0
            o.frame_id = "map" if cid == "POSE_MAP" else "odom"
            put(cid, u, o)
        if with_state:
            s = t.vehicle_state_t()
            s.utime = u
            s.fault_flags = (1 << 3) if i >= 80 else 0
            s.mode = 2 if i >= 80 else 1
            put("STATE", u, s)
        put("IMU", u, t.imu_t())
        cmd = t.vehicle_command_t()
        cmd.mac = bytes(16)
        put("COMMAND", u, cmd)
        if i % 10 == 0:
            c = t.control_status_t()
            c.utime, c.holder = u, "" if 40 <= i < 50 else "teleop"
            c.applied = i
            put("CONTROL", u, c)
            put("LIDAR", u, t.lidar_scan_t())
            v = t.v2v_state_t()
            put("V2V", u, v)
    log.close()


def test_check_run_reports_planted_events(build_dir: Path, tmp_path: Path) -> None:
    log = tmp_path / "run.lcmlog"
    write_log(log, build_dir)
    r, cars = check_run.report(log, build_dir, run="teleop")
    print(json.dumps(r, indent=1)[:3000])
    car = r["cars"][VEH]
    assert abs(car["distance_m"] - 1.0) < 1e-6 and car["distance_from"] == "GROUND_TRUTH"
    assert car["collisions"] == 2 and abs(car["collision_s"] - 0.26) < 0.03
    assert [h["holder"] for h in car["lease_holders"]] == ["teleop", "(none)", "teleop"]
    assert car["faults"] == {"bit 3": 21} and abs(car["failsafe_at_s"] - 1.6) < 1e-6
    frame = car["frames"]["POSE_MAP"]
    assert frame["frame"].startswith("its own start frame"), frame
    assert frame["median_error_to_ground_truth_m"] < 1e-6, "POSE_MAP not moved onto the map frame"
    moved = check_run.in_map_frame(cars[VEH])["POSE_MAP"]
    assert abs(moved[0][1] - 2.0) < 1e-9 and abs(moved[-1][1] - 3.0) < 1e-9
    assert abs(r["channels"]["NIGEL1_GROUND_TRUTH"]["rate_hz"] - 50.5) < 0.01
    assert r["channel_problems"] == [], r["channel_problems"]
    png = tmp_path / "run.png"
    rc = subprocess.run(
        [sys.executable, "-m", "autodrive.devtools.inspect.check_run", str(log), "--build",
         str(build_dir), "--map", "parking_school", "--run", "teleop"],
        capture_output=True, text=True,
    )  # fmt: skip
    print(rc.stdout, rc.stderr)
    assert rc.returncode == 0 and "drove 1.0 m (GROUND_TRUTH), collisions 2" in rc.stdout
    assert png.stat().st_size > 5000, "no picture"


def test_audit_per_kind_of_run(build_dir: Path, tmp_path: Path) -> None:
    log = tmp_path / "run.lcmlog"
    write_log(log, build_dir)
    full, _ = channel_audit.audit(log, build_dir, [VEH])
    assert any("CAM_FRONT" in p for p in full) and any("SIM_CLOCK" in p for p in full), full
    bare = tmp_path / "no_state.lcmlog"
    write_log(bare, build_dir, with_state=False)
    teleop, _ = channel_audit.audit(bare, build_dir, [VEH], run="teleop")
    assert teleop == ["NIGEL1_STATE: live in channels.yaml but nobody published it"], teleop


def test_export_mcap_names_its_output(build_dir: Path, tmp_path: Path) -> None:
    log = tmp_path / "run.lcmlog"
    write_log(log, build_dir)
    rc = subprocess.run(
        [sys.executable, "-m", "autodrive.devtools.inspect.export_mcap", str(log), "--build",
         str(build_dir)],
        capture_output=True, text=True,
    )  # fmt: skip
    assert rc.returncode == 0, rc.stderr
    assert (tmp_path / "run.mcap").stat().st_size > 1000


def test_export_mcap_places_an_unstamped_marker_at_its_log_time(
    build_dir: Path, tmp_path: Path
) -> None:
    # EYE_FRAME_DONE says "ready" with utime -1 (the Eye in lockstep); MCAP's times are unsigned
    from autodrive.devtools.inspect.export_mcap import export_mcap

    log = tmp_path / "ready.lcmlog"
    t = lcmtypes.load(build_dir)
    ev = lcm.EventLog(str(log), "w", overwrite=True)
    for utime in (-1, 2_000_000):
        done = t.eye_frame_done_t()
        done.utime = utime
        ch = channels.load().by_id("EYE_FRAME_DONE").resolve(None)
        ev.write_event(1_000_000 + max(utime, 0), ch, done.encode())
    ev.close()
    counts = export_mcap(log, tmp_path / "ready.mcap", build_dir)
    assert any("EYE_FRAME_DONE" in topic.upper() for topic in counts), counts
