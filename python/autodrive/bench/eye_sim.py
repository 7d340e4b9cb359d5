"""The Eye on the simulator's overhead camera: runs `autodrive-sim --eye` (real time, a scripted
car driving a circle under the camera) and `autodrive-eye run --source lcm:EYE_IMAGE`, and
compares every <VEH>_POSE_EYE with <VEH>_GROUND_TRUTH interpolated at the pose's utime (the
frame's capture time). Intrinsics from the sim's EYE_CAMERA_INFO (checked against the camera's
MJCF: 1280x960, fovy 60 deg); extrinsics from the MJCF camera pose (2.5 m above the origin,
looking down, image up = map +y), not from calibrate-map (the sim maps carry no floor tags).

CLI: python -m autodrive.bench.eye_sim <build dir> [duration_s] [out prefix for
.csv/.png]. Progress on stderr; "key value" lines on stdout. Run by `tools/bench eye` and the
test eye.Sim.OverheadCameraMatchesGroundTruth (EYE_SIM_PORT picks the LCM port)."""

from __future__ import annotations

import argparse
import bisect
import math
import os
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

from autodrive.core import lcmtypes, plots, proc
from autodrive.core.channels import channel, vehicle_name
from autodrive.core.geometry import wrap
from autodrive.hil.scoring import rms
from autodrive.bench import Progress

# eye's port range 7790-7809: 7798 for the benchmark, EYE_SIM_PORT=7797 for the test
DEFAULT_PORT = "7798"
W_PX, H_PX, FOVY_DEG, CAM_Z_M = 1280, 960, 60.0, 2.5
VEHICLE = vehicle_name(1)
TAG_ID = 1
RECV_BUF_BYTES = 4194304  # the socket also gets the JPEG frames
EYE_START_S = 1.0
EYE_IDLE_TIMEOUT_S = 6
CAR_SCRIPT = "constant:throttle=0.6,steering=-0.35,start=0.5"
log = Progress("eye sim")


def intrinsics() -> list[float]:
    f = 0.5 * H_PX / math.tan(math.radians(FOVY_DEG / 2))
    return [f, 0, 0.5 * (W_PX - 1), 0, f, 0.5 * (H_PX - 1), 0, 0, 1]


def write_eye_config(tmp: Path, url: str) -> Path:
    k = intrinsics()
    (tmp / "camera.yaml").write_text(
        f"width_px: {W_PX}\nheight_px: {H_PX}\nk: {k}\ndist: [0, 0, 0, 0, 0]\n"
    )
    # camera x = map x, camera y (image down) = map -y, optical axis = map -z, centre (0,0,2.5)
    (tmp / "map.yaml").write_text(
        f"width_px: {W_PX}\nheight_px: {H_PX}\nr_cam_map: [1, 0, 0, 0, -1, 0, 0, 0, -1]\n"
        f"t_cam_map_m: [0, 0, {CAM_Z_M}]\n"
    )
    (tmp / "eye.yaml").write_text(
        f'intrinsics: camera.yaml\nmap: map.yaml\nlcm_url: "{url}"\n'
        f"base_link_height_m: 0.0\nvehicles:\n - {{name: {VEHICLE}, tag_id: {TAG_ID}}}\n"
    )
    return tmp / "eye.yaml"


class Recorder:
    """Ground truth, Eye poses and camera infos from the bus, on a thread."""

    def __init__(
        self, build: Path, url: str, vehicle: str = VEHICLE, info_channels: list[str] | None = None
    ) -> None:
        types = lcmtypes.load(build)
        self.truth: list[Any] = []
        self.poses: list[Any] = []
        self.info: list[Any] = []
        self.status: list[Any] = []  # the Eye's EYE_CAMERA_STATUS messages
        self.lc = lcmtypes.bus(f"{url}&recv_buf_size={RECV_BUF_BYTES}")
        subs = [
            (channel("GROUND_TRUTH", vehicle), types.ground_truth_t, self.truth),
            (channel("POSE_EYE", vehicle), types.pose2d_t, self.poses),
            (channel("EYE_CAMERA_STATUS"), types.eye_camera_status_t, self.status),
        ]
        for ch in info_channels or [channel("EYE_CAMERA_INFO")]:
            subs.append((ch, types.camera_info_t, self.info))
        for ch, typ, into in subs:
            self.lc.subscribe(ch, lambda _c, d, t=typ, to=into: to.append(t.decode(d)))
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self._pump, daemon=True)
        self.thread.start()

    def _pump(self) -> None:
        while not self.stop.is_set():
            self.lc.handle_timeout(50)

    def close(self) -> None:
        self.stop.set()
        self.thread.join()


def run_eye_and_sim(build: Path, duration_s: float, tmp: Path, url: str) -> int:
    """Runs the Eye on the simulator's overhead camera; the number of frames it processed."""
    eye = subprocess.Popen(
        [str(build / "bin" / "autodrive-eye"), "run", "-c", str(write_eye_config(tmp, url))]
        + ["--source", f"lcm:{channel('EYE_IMAGE')}"]
        + ["--idle-timeout-s", str(EYE_IDLE_TIMEOUT_S), "-q"],
        stderr=subprocess.PIPE,
        text=True,
    )
    time.sleep(EYE_START_S)
    log(f"autodrive-sim --eye for {duration_s} s (real time), car on a right-hand circle")
    sim = subprocess.run(
        [str(build / "bin" / "autodrive-sim"), "--eye", "--camera-fps", "30"]
        + ["--duration", str(duration_s), "--lcm-url", url, "--run-dir", str(tmp / "run")]
        + ["--quiet", "--script", CAR_SCRIPT],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    if sim.returncode != 0:
        proc.stop(eye, "autodrive-eye", log)
        raise RuntimeError(f"autodrive-sim failed: {sim.stderr[-2000:]}")
    _, eye_err = eye.communicate(timeout=120)
    frames = 0
    for line in eye_err.splitlines():
        if "frames," in line:
            frames = int(line.split(":")[1].split()[0])
    log(eye_err.strip().splitlines()[-1] if eye_err.strip() else "eye printed nothing")
    return frames


Row = tuple[int, float, float, float, float, float, float]


def match(truth: list[Any], poses: list[Any]) -> list[Row]:
    """(utime, true x, y, yaw, Eye x, y, yaw) per Eye pose, the truth interpolated at its
    utime; poses outside the truth's span are left out."""
    truth = sorted(truth, key=lambda m: m.utime)
    tu = [m.utime for m in truth]
    rows = []
    for p in poses:
        i = bisect.bisect_left(tu, p.utime)
        if i == 0 or i >= len(tu):
            continue
        a, b = truth[i - 1], truth[i]
        s = (p.utime - a.utime) / max(1, b.utime - a.utime)
        x = a.position_m[0] + s * (b.position_m[0] - a.position_m[0])
        y = a.position_m[1] + s * (b.position_m[1] - a.position_m[1])
        yaw = a.yaw_rad + s * wrap(b.yaw_rad - a.yaw_rad)
        rows.append((p.utime, x, y, yaw, p.x_m, p.y_m, p.yaw_rad))
    return rows


def measure(build: Path, duration_s: float, prefix: str | None) -> dict[str, float]:
    """The sim_* figures; RuntimeError when the run cannot be measured."""
    for prog in ("autodrive-sim", "autodrive-eye"):
        if not os.access(build / "bin" / prog, os.X_OK):
            raise RuntimeError(f"{build / 'bin' / prog} not built")
    url = f"udpm://239.255.76.67:{os.environ.get('EYE_SIM_PORT', DEFAULT_PORT)}?ttl=0"
    rec = Recorder(build, url)
    with tempfile.TemporaryDirectory(prefix="eye-sim-") as tmp:
        try:
            frames = run_eye_and_sim(build, duration_s, Path(tmp), url)
            time.sleep(0.5)
        finally:
            rec.close()
    k = intrinsics()
    if rec.info:
        ki = list(rec.info[-1].k)
        if max(abs(a - b) for a, b in zip(ki, k)) > 1e-6 or rec.info[-1].width_px != W_PX:
            raise RuntimeError(f"EYE_CAMERA_INFO {ki} differs from the MJCF camera {k}")
    rows = match(rec.truth, rec.poses)
    if not rows:
        raise RuntimeError(
            f"no Eye pose matched the ground truth ({len(rec.poses)} poses, "
            f"{len(rec.truth)} truth, {frames} frames)"
        )
    errs_mm = [1000 * math.hypot(r[4] - r[1], r[5] - r[2]) for r in rows]
    errs_deg = [math.degrees(abs(wrap(r[6] - r[3]))) for r in rows]
    xs, ys = [r[1] for r in rows], [r[2] for r in rows]
    fig = {
        "sim_frames": frames,
        "sim_poses": len(rec.poses),
        "sim_detect_rate": round(len(rec.poses) / frames if frames else 0, 4),
        "sim_pos_rms_mm": round(rms(errs_mm), 3),
        "sim_pos_median_mm": round(sorted(errs_mm)[len(rows) // 2], 3),
        "sim_pos_max_mm": round(max(errs_mm), 3),
        "sim_heading_rms_deg": round(rms(errs_deg), 4),
        "sim_path_extent_x_m": round(max(xs) - min(xs), 3),
        "sim_path_extent_y_m": round(max(ys) - min(ys), 3),
    }
    if prefix:
        with open(prefix + ".csv", "w") as fh:
            fh.write("utime,true_x_m,true_y_m,true_yaw_rad,eye_x_m,eye_y_m,eye_yaw_rad\n")
            for r in rows:
                fh.write(",".join(str(v) for v in r) + "\n")
        t_s = [(r[0] - rows[0][0]) / 1e6 for r in rows]
        plots.eye_sim(
            Path(prefix + ".png"),
            (xs, ys),
            ([r[4] for r in rows], [r[5] for r in rows]),
            t_s,
            errs_mm,
        )
        log(f"plot {prefix}.png")
    return {k: float(v) for k, v in fig.items()}


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(
        prog="python -m autodrive.bench.eye_sim",
        description="The Eye on the simulator's overhead camera against its ground truth; "
        "prints 'key value' lines (sim_*).",
    )
    p.add_argument("build", type=Path, help="host build dir")
    p.add_argument("duration_s", type=float, nargs="?", default=20.0, help="sim time [s]")
    p.add_argument("prefix", nargs="?", help="write PREFIX.csv and PREFIX.png")
    a = p.parse_args(argv)
    try:
        fig = measure(a.build, a.duration_s, a.prefix)
    except RuntimeError as e:
        print(f"sim_eye: {e}", file=sys.stderr)
        return 1
    for k, v in fig.items():
        print(f"{k} {v:g}" if k in ("sim_frames", "sim_poses") else f"{k} {v}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
