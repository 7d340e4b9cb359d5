"""eye.Sim.BumpedCameraIsFlagged: Tiny Town's cameras calibrated from its reference tags, then
eye1's calibration moved by 5 mm and 0.3 deg (as if the camera had been bumped after it was
calibrated): on the simulator's rendered frames the Eye marks eye1 moved within 30 frames,
inflates its poses' covariance, and marks no other camera (autodrive.bench.eye_multi
--bump)."""
from pathlib import Path

import pytest

from autodrive.bench import eye_multi


def test_bumped_camera_is_flagged(build_dir: Path) -> None:
    try:
        fig = eye_multi.bumped_camera(build_dir)
    except RuntimeError as e:
        pytest.fail(f"FAIL: {e}")
    print("\n".join(f"{k} {v:g}" for k, v in fig.items()))
    fails = []
    if fig["sim_bumped_camera_detected"] != 1:
        fails.append(
            f"eye1 not marked moved within 30 frames ({fig['sim_bumped_camera_frames']:g})"
        )
    if fig["sim_bumped_camera_cov_scale"] <= 1:
        fails.append("the moved camera's poses carry no inflated covariance")
    if fig["sim_unmoved_cameras_no_alarm"] != 1:
        fails.append("an unmoved camera was marked moved")
    assert not fails, "FAIL: " + "; ".join(fails)
    print("PASS")
