"""eye.Sim.OverheadCameraMatchesGroundTruth: autodrive-sim --eye (real time, scripted car) and
autodrive-eye run on EYE_IMAGE; every NIGEL1_POSE_EYE vs the sim's ground truth at its utime."""
import subprocess
import sys
from pathlib import Path

import pytest


def test_overhead_camera_matches_ground_truth(build_dir: Path, pytestconfig: pytest.Config) -> None:
    build, dur = str(build_dir), pytestconfig.getoption("duration_s")
    r = subprocess.run(
        [sys.executable, "-m", "autodrive.bench.eye_sim", build, dur],
        capture_output=True,
        text=True,
        timeout=300,
    )
    sys.stderr.write(r.stderr)
    print(r.stdout)
    assert r.returncode == 0, f"FAIL: autodrive.bench.eye_sim exited {r.returncode}"
    fig = {k: float(v) for k, v in (line.split() for line in r.stdout.splitlines() if line.strip())}
    fails = []
    if fig["sim_frames"] < 10:
        fails.append(f"only {fig['sim_frames']} frames processed")
    if fig["sim_detect_rate"] < 0.99:
        fails.append(f"detect rate {fig['sim_detect_rate']} < 0.99")
    if fig["sim_pos_rms_mm"] > 5.0:
        fails.append(f"position rms {fig['sim_pos_rms_mm']} mm > 5")
    if fig["sim_heading_rms_deg"] > 0.5:
        fails.append(f"heading rms {fig['sim_heading_rms_deg']} deg > 0.5")
    if fig["sim_path_extent_x_m"] < 0.05:
        fails.append("the car did not move")
    assert not fails, "FAIL: " + "; ".join(fails)
    print("PASS")
