"""Analyses a demo LCM log: EKF estimate against simulator ground truth, collisions, telemetry
rate; writes PNG plots. Used by tools/demo.py; also runnable on any recorded log:
    .venv/bin/python tools/demo_report.py <run.lcmlog> <out-dir> [VEHICLE]"""
import bisect
import math
import pathlib
import statistics
import sys

import lcm


def _wrap(a):
    return (a + math.pi) % (2 * math.pi) - math.pi


def analyse(log_path, out, veh):
    from autodrive import ground_truth_t, odometry_t, vehicle_state_t

    out = pathlib.Path(out)
    gt, ekf, state_t = [], [], []
    faults_seen = 0
    collisions, in_collision = 0, False
    if not pathlib.Path(log_path).exists():
        return {"ok": False, "error": f"no LCM log at {log_path}"}
    for ev in lcm.EventLog(str(log_path), "r"):
        if ev.channel == f"{veh}_GROUND_TRUTH":
            m = ground_truth_t.decode(ev.data)
            gt.append((m.utime, m.position_m[0], m.position_m[1], m.yaw_rad))
            if m.in_collision and not in_collision:
                collisions += 1
            in_collision = m.in_collision
        elif ev.channel == f"{veh}_POSE_MAP":
            m = odometry_t.decode(ev.data)
            ekf.append((ev.timestamp, m.x_m, m.y_m, m.yaw_rad))
        elif ev.channel == f"{veh}_STATE":
            m = vehicle_state_t.decode(ev.data)
            state_t.append(m.nano_time_us)  # the Nano's clock: sim time in HIL
            faults_seen |= m.fault_flags
    rep = {
        "ok": False,
        "gt_samples": len(gt),
        "ekf_samples": len(ekf),
        "state_samples": len(state_t),
        "collisions": collisions,
        "fault_flags_seen": faults_seen,
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
    # Ground truth is stamped in sim time, EKF messages by receive time in the log: pair them by
    # log receive time, using the GT message's own receive time.
    gt_rx = []
    for ev in lcm.EventLog(str(log_path), "r"):
        if ev.channel == f"{veh}_GROUND_TRUTH":
            gt_rx.append(ev.timestamp)

    # The EKF map frame starts where the runtime started it; align it once, at the first pair.
    def gt_at(t):
        i = min(max(bisect.bisect_left(gt_rx, t), 0), len(gt) - 1)
        return gt[i]

    e0, g0 = ekf[0], gt_at(ekf[0][0])
    dyaw = _wrap(g0[3] - e0[3])
    c, s = math.cos(dyaw), math.sin(dyaw)
    aligned, errs_p, errs_h = [], [], []
    for t, x, y, yaw in ekf:
        xm = g0[1] + c * (x - e0[1]) - s * (y - e0[2])
        ym = g0[2] + s * (x - e0[1]) + c * (y - e0[2])
        g = gt_at(t)
        aligned.append((xm, ym))
        errs_p.append(math.hypot(xm - g[1], ym - g[2]))
        errs_h.append(math.degrees(_wrap(yaw + dyaw - g[3])))
    rep["ekf_pos_rms_m"] = round(math.sqrt(sum(e * e for e in errs_p) / len(errs_p)), 4)
    rep["ekf_heading_rms_deg"] = round(math.sqrt(sum(e * e for e in errs_h) / len(errs_h)), 3)
    rep["ekf_final_pos_error_m"] = round(errs_p[-1], 4)
    rep["ok"] = rep["path_length_m"] > 1.0 and collisions == 0
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(7, 6))
        ax.plot([g[1] for g in gt], [g[2] for g in gt], "k-", lw=2, label="ground truth (sim)")
        ax.plot(
            [a[0] for a in aligned],
            [a[1] for a in aligned],
            "r--",
            lw=1,
            label="runtime EKF (wheel odometry + IMU)",
        )
        ax.set_aspect("equal")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.set_title(
            f"{veh} HIL drive: path {rep['path_length_m']} m, EKF RMS "
            f"{rep['ekf_pos_rms_m'] * 100:.1f} cm / {rep['ekf_heading_rms_deg']:.1f} deg"
        )
        ax.grid(True, alpha=0.3)
        ax.legend()
        fig.tight_layout()
        fig.savefig(out / "trajectory.png", dpi=110)
        plt.close(fig)
        fig, ax = plt.subplots(figsize=(7, 3))
        tt = [(t - ekf[0][0]) / 1e6 for t, *_ in ekf]
        ax.plot(tt, [e * 100 for e in errs_p], label="position error [cm]")
        ax.plot(tt, errs_h, label="heading error [deg]")
        ax.set_xlabel("time [s, wall]")
        ax.grid(True, alpha=0.3)
        ax.legend()
        fig.tight_layout()
        fig.savefig(out / "ekf_error.png", dpi=110)
        plt.close(fig)
    except ImportError as e:
        rep["plot_error"] = str(e)
    return rep


if __name__ == "__main__":
    import json

    if len(sys.argv) < 3 or sys.argv[1] in ("-h", "--help"):
        print(__doc__)
        sys.exit(0 if len(sys.argv) > 1 else 2)
    print(
        json.dumps(
            analyse(sys.argv[1], sys.argv[2], sys.argv[3] if len(sys.argv) > 3 else "NIGEL1"),
            indent=2,
        )
    )
