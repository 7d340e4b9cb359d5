#!/usr/bin/env python3
"""eye.Sim.BumpedCameraIsFlagged: Tiny Town's cameras calibrated from its reference tags, then
eye1's calibration moved by 5 mm and 0.3 deg (as if the camera had been bumped after it was
calibrated): on the simulator's rendered frames the Eye marks eye1 moved within 30 frames,
inflates its poses' covariance, and marks no other camera (autodrive.bench.eye_multi
--bump). Usage: test_sim_bumped.py <build dir>"""
import sys
from pathlib import Path

from autodrive.bench import eye_multi

try:
    fig = eye_multi.bumped_camera(Path(sys.argv[1]))
except RuntimeError as e:
    sys.exit(f"FAIL: {e}")
print("\n".join(f"{k} {v:g}" for k, v in fig.items()))
fails = []
if fig["sim_bumped_camera_detected"] != 1:
    fails.append(f"eye1 not marked moved within 30 frames ({fig['sim_bumped_camera_frames']:g})")
if fig["sim_bumped_camera_cov_scale"] <= 1:
    fails.append("the moved camera's poses carry no inflated covariance")
if fig["sim_unmoved_cameras_no_alarm"] != 1:
    fails.append("an unmoved camera was marked moved")
if fails:
    sys.exit("FAIL: " + "; ".join(fails))
print("PASS")
