"""autodrive-sim --camera-exposure EV (issue 38): the cars' published camera frames are the
frames multiplied by 2^EV (darker at -1, brighter and clipped at +1), while the Eye's frames of
the same run stay byte for byte. The real program in free lockstep, its LCM on a file:// log
(no network), judged by the decoded JPEGs' pixels only."""

from __future__ import annotations

import subprocess
from pathlib import Path

import cv2
import numpy as np

from autodrive.core import lcmtypes

FRONT, EYE = "NIGEL1_CAM_FRONT", "EYE_IMAGE"


def _frames(build_dir: Path, tmp_path: Path, ev: float) -> dict[str, list[np.ndarray]]:
    log = tmp_path / f"ev{ev:+g}.lcmlog"
    r = subprocess.run(
        [str(build_dir / "bin" / "autodrive-sim"), "--map", "driving_school", "--lockstep",
         "--duration", "0.2", "--no-pty", "--no-lidar", "--quiet", "--front-camera", "--eye",
         "--camera-exposure", str(ev), "--run-dir", str(tmp_path),
         "--lcm-url", f"file://{log}?mode=w"],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert r.returncode == 0, r.stderr[-2000:]
    t = lcmtypes.load(build_dir)
    out: dict[str, list[np.ndarray]] = {FRONT: [], EYE: []}
    for e in lcmtypes.events(log):
        if e.channel in out:
            m = t.compressed_image_t.decode(e.data)
            out[e.channel].append(cv2.imdecode(np.frombuffer(m.data, np.uint8), cv2.IMREAD_COLOR))
    assert out[FRONT] and out[EYE], {k: len(v) for k, v in out.items()}
    return out


def test_exposure_scales_the_cars_frames_and_leaves_the_eye(
    build_dir: Path, tmp_path: Path
) -> None:
    base, dark, bright = (_frames(build_dir, tmp_path, ev) for ev in (0.0, -1.0, 1.0))
    f0 = base[FRONT][-1].astype(float)
    f_dark, f_bright = dark[FRONT][-1].astype(float), bright[FRONT][-1].astype(float)
    # -1 EV halves every level (JPEG's error aside)
    assert abs(f_dark.mean() / f0.mean() - 0.5) < 0.03, (f_dark.mean(), f0.mean())
    # +1 EV doubles the dark levels and clips the bright ones at 255
    low, high = f0 < 100, f0 > 160
    assert abs(np.median(f_bright[low] / np.maximum(f0[low], 1)) - 2.0) < 0.15
    assert np.median(f_bright[high]) >= 250
    # the Eye's frames are the same bytes whatever the cars' exposure
    for run in (dark, bright):
        assert len(run[EYE]) == len(base[EYE])
        for a, b in zip(run[EYE], base[EYE]):
            assert np.array_equal(a, b)
