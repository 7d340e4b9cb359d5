"""Tiny Town's overhead cameras calibrated into one map frame from its shared reference tags, as
a user would: `autodrive-sim --map tiny_town --eye` renders every camera (<CAM>_IMAGE), one
frame of each is kept, and `autodrive-eye calibrate-map` solves each camera's pose from the
reference tags it sees (the map sidecar's reference_tags, written by tools/gen-maps from the
map description); then, for every pair of cameras that share a tag, `calibrate-map
--overlap-*` reports how far apart the two calibrations put the shared tags' corners.
Against the map's camera poses (the simulator's truth): each calibrated camera centre's error.

CLI: python -m autodrive.bench.eye_refcal <build dir> [out dir]. Run by
`tools/bench eye` and the test eye.Sim.CamerasCalibrateFromReferenceTags (EYE_REFCAL_PORT
picks the LCM port). Progress on stderr; "key value" lines on stdout; the calibrations in the
out dir when given."""

from __future__ import annotations

import argparse
import itertools
import json
import math
import os
import re
import subprocess
import sys
import tempfile
import threading
from pathlib import Path
from typing import Any

from autodrive.maps import eye_cameras
from autodrive.core import lcmtypes
from autodrive.maps.loader import MAPS_DIR
from autodrive.bench import Progress, key_value_main

MAP = "tiny_town"
# eye's port range 7790-7809: 7801 for the benchmark, EYE_REFCAL_PORT for the test
DEFAULT_PORT = "7801"
SIM_S, CAMERA_FPS = 1.0, 4.0  # a few frames of each camera: one is enough, the last is kept
RECV_BUF_BYTES = 8388608
log = Progress("eye refcal")


def reference_tags(map_name: str) -> list[dict[str, Any]]:
    """The map's reference tags (sidecar: id, x_m, y_m, z_m, yaw_rad, size_m)."""
    return eye_cameras.reference_tags(map_name, MAPS_DIR)


def write_tags(tags: list[dict[str, Any]], path: Path) -> None:
    path.write_text(eye_cameras.tags_text(tags))


def grab_frames(
    build: Path, tmp: Path, url: str, cams: list[eye_cameras.OverheadCamera]
) -> dict[str, bytes]:
    """The last JPEG of each camera from a short simulator run."""
    frames: dict[str, bytes] = {}
    lc = lcmtypes.bus(f"{url}&recv_buf_size={RECV_BUF_BYTES}")
    types = lcmtypes.load(build)
    for c in cams:
        lc.subscribe(
            c.image_channel(),
            lambda _ch, d, n=c.name: frames.__setitem__(n, bytes(types.compressed_image_t.decode(d).data)),
        )  # fmt: skip
    stop = threading.Event()

    def pump() -> None:
        while not stop.is_set():
            lc.handle_timeout(50)

    th = threading.Thread(target=pump, daemon=True)
    th.start()
    log(f"autodrive-sim --map {MAP} --eye: {SIM_S:g} s of sim time at {CAMERA_FPS:g} fps")
    sim = subprocess.run(
        [str(build / "bin" / "autodrive-sim"), "--map", MAP, "--eye"]
        + ["--camera-fps", str(CAMERA_FPS), "--no-lidar", "--no-late-obstacles"]
        + ["--duration", str(SIM_S), "--lcm-url", url, "--run-dir", str(tmp / "run")]
        + ["--quiet", "--no-pty"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    stop.set()
    th.join()
    if sim.returncode != 0:
        raise RuntimeError(f"autodrive-sim failed: {sim.stderr[-2000:]}")
    missing = [c.name for c in cams if c.name not in frames]
    if missing:
        raise RuntimeError(f"no frame from camera(s) {missing}")
    return frames


def calibrate(build: Path, args: list[str]) -> str:
    r = subprocess.run(
        [str(build / "bin" / "autodrive-eye"), "calibrate-map", *args],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    if r.returncode != 0:
        raise RuntimeError(f"calibrate-map {' '.join(args)} failed: {r.stdout[-1500:]}")
    return r.stdout


def number_after(text: str, pattern: str) -> float:
    m = re.search(pattern, text)
    if not m:
        raise RuntimeError(f"calibrate-map printed no '{pattern}': {text[-800:]}")
    return float(m.group(1))


def measure(build: Path, out: Path | None = None) -> dict[str, float]:
    """The refcal_* and overlap figures; RuntimeError when they cannot be measured."""
    for prog in ("autodrive-sim", "autodrive-eye"):
        if not os.access(build / "bin" / prog, os.X_OK):
            raise RuntimeError(f"{build / 'bin' / prog} not built")
    cams = eye_cameras.load(MAP)
    tags = reference_tags(MAP)
    if len(cams) < 2 or not tags:
        raise RuntimeError(f"map {MAP}: {len(cams)} eye_cameras, {len(tags)} reference_tags")
    url = f"udpm://239.255.76.67:{os.environ.get('EYE_REFCAL_PORT', DEFAULT_PORT)}?ttl=0"
    with tempfile.TemporaryDirectory(prefix="eye-refcal-") as tmp_s:
        tmp = out if out is not None else Path(tmp_s)
        tmp.mkdir(parents=True, exist_ok=True)
        write_tags(tags, tmp / "reference_tags.yaml")
        frames = grab_frames(build, Path(tmp_s), url, cams)
        res: dict[str, dict[str, float]] = {}
        for c in cams:
            intr, _ = c.write_calibration(tmp)  # intrinsics: the sim camera's; the pose: solved
            (tmp / c.name).mkdir(exist_ok=True)
            (tmp / c.name / "frame.jpg").write_bytes(frames[c.name])
            text = calibrate(
                build,
                ["--intrinsics", str(intr), "--tags", str(tmp / "reference_tags.yaml")]
                + ["--images", str(tmp / c.name), "-o", str(tmp / f"{c.name}_calibrated.yaml")],
            )
            m = re.search(r"camera centre on the map \(([-\d.]+), ([-\d.]+), ([-\d.]+)\)", text)
            if not m:
                raise RuntimeError(f"{c.name}: calibrate-map printed no camera centre: {text}")
            cx, cy, cz = (float(v) for v in m.groups())
            err_mm = 1000 * math.dist((cx, cy, cz), (c.x_m, c.y_m, c.z_m))
            res[c.name] = {
                "tags": number_after(text, r"over (\d+) tags"),
                "rms_mm": number_after(text, r"residual rms ([\d.]+) mm"),
                "centre_mm": err_mm,
            }
            log(
                f"{c.name}: {res[c.name]['tags']:g} tags, residual {res[c.name]['rms_mm']:.3f} mm "
                f"rms, centre {err_mm:.1f} mm from the map's"
            )
        pairs: list[float] = []
        for a, b in itertools.combinations(cams, 2):
            text = calibrate(
                build,
                ["--intrinsics", str(tmp / f"{a.name}_camera.yaml")]
                + ["--tags", str(tmp / "reference_tags.yaml"), "--images", str(tmp / a.name)]
                + ["-o", str(tmp / f"{a.name}_calibrated.yaml")]
                + ["--overlap-map", str(tmp / f"{b.name}_calibrated.yaml")]
                + ["--overlap-intrinsics", str(tmp / f"{b.name}_camera.yaml")]
                + ["--overlap-images", str(tmp / b.name)],
            )
            if "no reference tag seen by both" in text:
                continue
            rms_mm = number_after(text, r"overlap: \d+ shared tags, ([\d.]+) mm rms")
            log(f"{a.name} + {b.name}: shared tags agree within {rms_mm:.3f} mm rms")
            pairs.append(rms_mm)
    if not pairs:
        raise RuntimeError("no two cameras share a reference tag")
    return {
        "refcal_cameras": float(len(res)),
        "refcal_tags_per_camera_min": min(r["tags"] for r in res.values()),
        "refcal_residual_rms_mm_max": round(max(r["rms_mm"] for r in res.values()), 3),
        "refcal_camera_centre_error_mm_max": round(max(r["centre_mm"] for r in res.values()), 2),
        "refcal_overlap_pairs": float(len(pairs)),
        "refcal_overlap_agreement_rms_mm_max": round(max(pairs), 3),
    }


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(
        prog="python -m autodrive.bench.eye_refcal",
        description="Calibrate Tiny Town's simulated overhead cameras from its reference tags "
        "(calibrate-map) and report how the cameras agree where they overlap; prints 'key "
        "value' lines (refcal_*).",
    )
    p.add_argument("build", type=Path, help="host build dir")
    p.add_argument("out", type=Path, nargs="?", help="keep frames and calibrations here")
    a = p.parse_args(argv)
    return key_value_main("eye_refcal", lambda: measure(a.build, a.out))


if __name__ == "__main__":
    sys.exit(main())
