#!/usr/bin/env python3
"""The Eye on the simulator's overhead camera: runs `autodrive-sim --eye` (real time, a scripted
car driving a circle under the camera) and `autodrive-eye run --source lcm:EYE_IMAGE`, and
compares every NIGEL1_POSE_EYE with NIGEL1_GROUND_TRUTH interpolated at the pose's utime (the
frame's capture time). Intrinsics from the sim's EYE_CAMERA_INFO (checked against the camera's
MJCF: 1280x960, fovy 60 deg); extrinsics from the MJCF camera pose (2.5 m above the origin,
looking down, image up = map +y), not from calibrate-map (the sim maps carry no floor tags).
Usage: sim_eye.py <build dir> [duration_s] [out prefix for .csv/.png]. Progress on stderr; "key value" lines on stdout."""
import math
import os
import subprocess
import sys
import tempfile
import threading
import time

BUILD = sys.argv[1]
DURATION_S = float(sys.argv[2]) if len(sys.argv) > 2 else 20.0
sys.path.insert(0, os.path.join(BUILD, "lcm_types", "gen", "python"))
import lcm  # noqa: E402
from autodrive import camera_info_t, ground_truth_t, pose2d_t  # noqa: E402

# eye's port range 7790-7809: 7798 for the benchmark, EYE_SIM_PORT=7797 for the test
URL = f"udpm://239.255.76.67:{os.environ.get('EYE_SIM_PORT', '7798')}?ttl=0"
W, H, FOVY_DEG, CAM_Z_M = 1280, 960, 60.0, 2.5


def log(m):
    print(f"[sim_eye] {m}", file=sys.stderr, flush=True)


def main():
    sim = os.path.join(BUILD, "bin", "autodrive-sim")
    eye = os.path.join(BUILD, "bin", "autodrive-eye")
    for p in (sim, eye):
        if not os.access(p, os.X_OK):
            sys.exit(f"sim_eye: {p} not built")
    tmp = tempfile.mkdtemp(prefix="eye-sim-")
    f = 0.5 * H / math.tan(math.radians(FOVY_DEG / 2))
    k = [f, 0, 0.5 * (W - 1), 0, f, 0.5 * (H - 1), 0, 0, 1]
    with open(os.path.join(tmp, "camera.yaml"), "w") as fh:
        fh.write(f"width_px: {W}\nheight_px: {H}\nk: {k}\ndist: [0, 0, 0, 0, 0]\n")
    # camera x = map x, camera y (image down) = map -y, optical axis = map -z, centre (0,0,2.5)
    with open(os.path.join(tmp, "map.yaml"), "w") as fh:
        fh.write(
            f"width_px: {W}\nheight_px: {H}\nr_cam_map: [1, 0, 0, 0, -1, 0, 0, 0, -1]\n"
            f"t_cam_map_m: [0, 0, {CAM_Z_M}]\n"
        )
    with open(os.path.join(tmp, "eye.yaml"), "w") as fh:
        fh.write(
            f'intrinsics: camera.yaml\nmap: map.yaml\nlcm_url: "{URL}"\n'
            "tag_size_m: 0.08\ntag_offset_m: [0.035125, 0.0, 0.129165]\n"
            "base_link_height_m: 0.0\nvehicles:\n - {name: NIGEL1, tag_id: 1}\n"
        )

    lc = lcm.LCM(URL + "&recv_buf_size=4194304")  # the socket also gets the JPEG frames
    truth, poses, info = [], [], []
    lc.subscribe("NIGEL1_GROUND_TRUTH", lambda c, d: truth.append(ground_truth_t.decode(d)))
    lc.subscribe("NIGEL1_POSE_EYE", lambda c, d: poses.append(pose2d_t.decode(d)))
    lc.subscribe("EYE_CAMERA_INFO", lambda c, d: info.append(camera_info_t.decode(d)))
    stop = threading.Event()

    def pump():
        while not stop.is_set():
            lc.handle_timeout(50)

    th = threading.Thread(target=pump, daemon=True)
    th.start()

    eye_p = subprocess.Popen(
        [
            eye,
            "run",
            "-c",
            os.path.join(tmp, "eye.yaml"),
            "--source",
            "lcm:EYE_IMAGE",
            "--idle-timeout-s",
            "6",
            "-q",
        ],
        stderr=subprocess.PIPE,
        text=True,
    )
    time.sleep(1.0)
    log(f"autodrive-sim --eye for {DURATION_S} s (real time), car on a right-hand circle")
    simp = subprocess.run(
        [
            sim,
            "--eye",
            "--camera-fps",
            "30",
            "--duration",
            str(DURATION_S),
            "--lcm-url",
            URL,
            "--run-dir",
            os.path.join(tmp, "run"),
            "--quiet",
            "--script",
            "constant:throttle=0.6,steering=-0.35,start=0.5",
        ],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    if simp.returncode != 0:
        sys.exit(f"sim_eye: autodrive-sim failed: {simp.stderr[-2000:]}")
    _, eye_err = eye_p.communicate(timeout=120)
    time.sleep(0.5)
    stop.set()
    th.join()
    frames = 0
    for line in eye_err.splitlines():
        if "frames," in line:
            frames = int(line.split(":")[1].split()[0])
    log(eye_err.strip().splitlines()[-1] if eye_err.strip() else "eye printed nothing")
    if info:
        ki = list(info[-1].k)
        if max(abs(a - b) for a, b in zip(ki, k)) > 1e-6 or info[-1].width_px != W:
            sys.exit(f"sim_eye: EYE_CAMERA_INFO {ki} differs from the MJCF camera {k}")
    truth.sort(key=lambda m: m.utime)
    tu = [m.utime for m in truth]
    import bisect

    errs_mm, errs_deg, rows = [], [], []
    for p in poses:
        i = bisect.bisect_left(tu, p.utime)
        if i == 0 or i >= len(tu):
            continue
        a, b = truth[i - 1], truth[i]
        s = (p.utime - a.utime) / max(1, b.utime - a.utime)
        x = a.position_m[0] + s * (b.position_m[0] - a.position_m[0])
        y = a.position_m[1] + s * (b.position_m[1] - a.position_m[1])
        dyaw = math.remainder(b.yaw_rad - a.yaw_rad, 2 * math.pi)
        yaw = a.yaw_rad + s * dyaw
        rows.append((p.utime, x, y, yaw, p.x_m, p.y_m, p.yaw_rad))
        errs_mm.append(1000 * math.hypot(p.x_m - x, p.y_m - y))
        errs_deg.append(math.degrees(abs(math.remainder(p.yaw_rad - yaw, 2 * math.pi))))
    n = len(errs_mm)
    if n == 0:
        sys.exit(
            f"sim_eye: no Eye pose matched the ground truth ({len(poses)} poses, {len(truth)} truth, {frames} frames)"
        )
    rms = math.sqrt(sum(e * e for e in errs_mm) / n)
    hrms = math.sqrt(sum(e * e for e in errs_deg) / n)
    print(f"sim_frames {frames}")
    print(f"sim_poses {len(poses)}")
    print(f"sim_detect_rate {len(poses) / frames if frames else 0:.4f}")
    print(f"sim_pos_rms_mm {rms:.3f}")
    print(f"sim_pos_median_mm {sorted(errs_mm)[n // 2]:.3f}")
    print(f"sim_pos_max_mm {max(errs_mm):.3f}")
    print(f"sim_heading_rms_deg {hrms:.4f}")
    xs, ys = [r[1] for r in rows], [r[2] for r in rows]
    print(f"sim_path_extent_x_m {max(xs) - min(xs):.3f}")
    print(f"sim_path_extent_y_m {max(ys) - min(ys):.3f}")
    if len(sys.argv) > 3:  # CSV and plot
        out = sys.argv[3]
        with open(out + ".csv", "w") as fh:
            fh.write("utime,true_x_m,true_y_m,true_yaw_rad,eye_x_m,eye_y_m,eye_yaw_rad\n")
            for r in rows:
                fh.write(",".join(str(v) for v in r) + "\n")
        try:
            import matplotlib

            matplotlib.use("Agg")
            import matplotlib.pyplot as plt

            fig, (a1, a2) = plt.subplots(1, 2, figsize=(12, 5))
            a1.plot(xs, ys, "-", color="0.6", lw=3, label="sim ground truth (base_link)")
            a1.plot([r[4] for r in rows], [r[5] for r in rows], ".", ms=3, label="Eye")
            a1.set_aspect("equal")
            a1.set_xlabel("map x [m]")
            a1.set_ylabel("map y [m]")
            a1.set_title("autodrive-sim overhead camera (1280x960), NIGEL1")
            a1.legend(fontsize=8)
            a2.plot([(r[0] - rows[0][0]) / 1e6 for r in rows], errs_mm, lw=1)
            a2.set_xlabel("sim time [s]")
            a2.set_ylabel("position error [mm]")
            a2.set_title("Eye vs ground truth")
            fig.tight_layout()
            fig.savefig(out + ".png", dpi=110)
            log(f"plot {out}.png")
        except ImportError:
            log("matplotlib missing: no plot")


if __name__ == "__main__":
    main()
