"""The demo's report of a recorded run: the runtime's EKF against the simulator's ground truth,
collisions, telemetry rate, path length, Eye poses; trajectory.png and ekf_error.png. The EKF
is its map filter (<VEH>_POSE_MAP), or its odometry (<VEH>_ODOM) in a run without an Eye.

Also runnable on any recorded log:
    python -m autodrive.hil.report <run.lcmlog> <out-dir> [VEHICLE] [--build DIR]"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import sys
from pathlib import Path
from typing import Any

from autodrive.core import lcmtypes, plots
from autodrive.core import channels
from autodrive.core.channels import channel
from autodrive.core.geometry import Alignment, wrap
from autodrive.core.settings import RELEASE_BUILD
from autodrive.hil import pose_source
from autodrive.hil.scoring import nearest_index, rms

Report = dict[str, Any]


def analyse(
    log_path: Path,
    out: Path,
    veh: str,
    build: Path,
    eye: str = "none",
    eye_what: str = "",
    eye_latency_ms: float | None = None,
    eye_sync_give_ups: int | None = None,
) -> Report:
    """eye: the run's --eye (its pose_source); eye_what: what ran (for the report);
    eye_latency_ms: the Eye's lockstep latency [ms of sim time], None when not in lockstep;
    eye_sync_give_ups: how often the sim gave the Eye up (pose_source.eye_sync_give_ups)."""
    if not Path(log_path).exists():
        return {"ok": False, "error": f"no LCM log at {log_path}"}
    types = lcmtypes.load(build)
    ch_truth, ch_pose, ch_state, ch_control, ch_odom, ch_eye = (
        channel(c, veh)
        for c in ("GROUND_TRUTH", "POSE_MAP", "STATE", "CONTROL", "ODOM", "POSE_EYE")
    )
    poses = pose_source.PoseRecord()
    odom: list[tuple[int, float, float, float]] = []  # (receive time [us], x, y, yaw)
    control: Any = None  # the bridge's last control_status_t
    holders: set[str] = set()
    # (sim time [us], x, y, yaw); gt_rx: the log's receive time of each
    gt: list[tuple[int, float, float, float]] = []
    gt_rx: list[int] = []
    ekf: list[tuple[int, float, float, float]] = []  # (receive time [us], x, y, yaw)
    state_t: list[int] = []
    faults_seen = 0
    collisions, in_collision = 0, False
    for ev in lcmtypes.events(log_path):
        if ev.channel == ch_truth:
            m = types.ground_truth_t.decode(ev.data)
            gt.append((m.utime, m.position_m[0], m.position_m[1], m.yaw_rad))
            gt_rx.append(ev.timestamp)
            poses.on_truth(veh, m.utime * 1e-6, m.position_m[0], m.position_m[1])
            if m.in_collision and not in_collision:
                collisions += 1
            in_collision = m.in_collision
        elif ev.channel == ch_pose:
            m = types.odometry_t.decode(ev.data)
            ekf.append((ev.timestamp, m.x_m, m.y_m, m.yaw_rad))
            poses.on_ekf(veh, m.utime * 1e-6, m.x_m, m.y_m)
        elif ev.channel == ch_odom:
            m = types.odometry_t.decode(ev.data)
            odom.append((ev.timestamp, m.x_m, m.y_m, m.yaw_rad))
        elif ev.channel == ch_eye:
            poses.on_eye(veh, types.pose2d_t.decode(ev.data).utime * 1e-6)
        elif ev.channel == ch_state:
            m = types.vehicle_state_t.decode(ev.data)
            state_t.append(m.nano_time_us)  # the Nano's clock: sim time in HIL
            faults_seen |= m.fault_flags
        elif ev.channel == ch_control:
            control = types.control_status_t.decode(ev.data)
            if control.holder:
                holders.add(control.holder)
    # No map pose without an Eye fix: then the EKF's odometry, aligned below as the map was.
    ekf_channel = ch_pose if len(ekf) >= 10 or len(odom) < 10 else ch_odom
    ekf = ekf if ekf_channel == ch_pose else odom
    rep: Report = {
        "ok": False,
        **pose_source.report(
            eye, eye_what or eye, [poses], [veh], eye_latency_ms, eye_sync_give_ups
        ),
        "ekf_channel": ekf_channel,
        "gt_samples": len(gt),
        "ekf_samples": len(ekf),
        "state_samples": len(state_t),
        "collisions": collisions,
        "fault_flags_seen": faults_seen,
        **command_figures(control, holders),
    }
    if len(gt) < 10 or len(ekf) < 10 or len(state_t) < 10:
        rep["error"] = "too few ground-truth/EKF/state messages in the log"
        return rep
    rep["sim_s"] = round((gt[-1][0] - gt[0][0]) / 1e6, 2)
    rep["path_length_m"] = round(
        sum(math.hypot(b[1] - a[1], b[2] - a[2]) for a, b in zip(gt, gt[1:])), 3
    )
    dts = [(b - a) / 1e3 for a, b in zip(state_t, state_t[1:]) if b > a]
    rep["telemetry_hz"] = round(1e3 / statistics.median(dts), 1)  # per second of Nano time

    # Ground truth is stamped in sim time, EKF messages by receive time in the log: pair them
    # by receive time. The EKF map frame starts where the runtime started it: align it once,
    # at the first pair.
    def gt_at(t: int) -> tuple[int, float, float, float]:
        return gt[nearest_index(gt_rx, t)]

    align = Alignment(ekf[0][1:], gt_at(ekf[0][0])[1:])
    aligned, errs_p, errs_h = [], [], []
    for t, x, y, yaw in ekf:
        xm, ym = align.point(x, y)
        g = gt_at(t)
        aligned.append((xm, ym))
        errs_p.append(math.hypot(xm - g[1], ym - g[2]))
        errs_h.append(math.degrees(wrap(yaw + align.dyaw_rad - g[3])))
    rep["ekf_pos_rms_m"] = round(rms(errs_p), 4)
    rep["ekf_heading_rms_deg"] = round(rms(errs_h), 3)
    rep["ekf_final_pos_error_m"] = round(errs_p[-1], 4)
    rep["ok"] = rep["path_length_m"] > 1.0 and collisions == 0 and rep["foreign_commands"] == 0
    plots.trajectory(
        out / "trajectory.png",
        veh,
        ([g[1] for g in gt], [g[2] for g in gt]),
        ([a[0] for a in aligned], [a[1] for a in aligned]),
        rep["path_length_m"],
        (rep["ekf_pos_rms_m"], rep["ekf_heading_rms_deg"]),
    )
    plots.ekf_error(out / "ekf_error.png", [(e[0] - ekf[0][0]) / 1e6 for e in ekf], errs_p, errs_h)
    return rep


def command_figures(control: Any, holders: set[str]) -> Report:
    """What the runtime's command gate saw (its last <VEH>_CONTROL): foreign_commands are the
    commands it dropped as unsigned, wrongly signed or replayed; a run with any is not a success."""
    if control is None:
        return {"foreign_commands": 0, "control_status_seen": False, "command_holders": []}
    return {
        "foreign_commands": control.dropped_unsigned
        + control.dropped_bad_mac
        + control.dropped_replay,
        "foreign_unsigned": control.dropped_unsigned,
        "foreign_bad_signature": control.dropped_bad_mac,
        "foreign_replayed": control.dropped_replay,
        "commands_not_holder": control.dropped_not_holder,
        "commands_applied": control.applied,
        "control_holder_changes": control.holder_changes,
        "command_holders": sorted(holders),
        "control_status_seen": True,
    }


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(
        prog="python -m autodrive.hil.report",
        description="Analyse a recorded demo LCM log (EKF vs ground truth, collisions, "
        "telemetry rate); writes trajectory.png and ekf_error.png into OUT and prints the "
        "report as JSON.",
    )
    p.add_argument("log", type=Path, help="the LCM log (run.lcmlog)")
    p.add_argument("out", type=Path, help="folder for the plots")
    p.add_argument(
        "vehicle", nargs="?", default=channels.vehicle_name(1), help="vehicle name (default car 1)"
    )
    p.add_argument("--build", type=Path, default=RELEASE_BUILD, help="build dir with the LCM types")
    a = p.parse_args(argv)
    a.out.mkdir(parents=True, exist_ok=True)
    print(json.dumps(analyse(a.log, a.out, a.vehicle, a.build), indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
