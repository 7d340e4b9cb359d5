"""eye.Sim.SeveralCamerasHandOverWithoutGap: autodrive-sim --map tiny_town --eye renders the
map's overhead cameras, a scripted car drives through the overlap of two of them, and one
autodrive-eye serves them all; its poses vs the sim's ground truth (autodrive.bench.
eye_multi, --drive crossing), each camera calibrated by calibrate-map from the town's reference
tags first; every camera publishes its status (reference residual within the health threshold,
none marked moved). """
from pathlib import Path

import pytest

from autodrive.bench import eye_multi


def test_cameras_hand_over_without_gap(build_dir: Path, pytestconfig: pytest.Config) -> None:
    build, dur = str(build_dir), pytestconfig.getoption("duration_s")
    try:
        fig = eye_multi.measure(Path(build), float(dur), None, "crossing")
    except RuntimeError as e:
        pytest.fail(f"FAIL: {e}")
    print("\n".join(f"{k} {v:g}" for k, v in fig.items()))
    fails = []
    if fig["sim_multi_cam_frames"] < 20:
        fails.append(f"only {fig['sim_multi_cam_frames']:g} frames processed")
    if fig["sim_multi_cam_cameras_crossed"] < 2 or fig["sim_multi_cam_handovers"] < 1:
        fails.append("the car was not handed from one camera to another")
    if fig["sim_multi_cam_frames_in_overlap"] < 1:
        fails.append("no frame with the car's tag in two cameras (no fused pose)")
    if fig["handover_gap_frames"] != 0:
        fails.append(f"{fig['handover_gap_frames']:g} frames without a pose while in view")
    if fig["multi_cam_pos_rms_mm"] > 2.0:
        fails.append(f"position rms {fig['multi_cam_pos_rms_mm']} mm > 2")
    if fig["sim_multi_cam_heading_rms_deg"] > 0.5:
        fails.append(f"heading rms {fig['sim_multi_cam_heading_rms_deg']} deg > 0.5")
    # Every camera was calibrated from the reference tags (eye_refcal) and reports its health.
    if fig["refcal_cameras"] != fig["sim_multi_cam_cameras"]:
        fails.append("not every camera was calibrated from the reference tags")
    if fig["sim_multi_cam_status_cameras"] != fig["sim_multi_cam_cameras"]:
        fails.append(f"EYE_CAMERA_STATUS from {fig['sim_multi_cam_status_cameras']:g} cameras only")
    if not 0 <= fig["sim_multi_cam_status_ref_residual_mm_max"] <= 3.0:
        fails.append(f"reference residual {fig['sim_multi_cam_status_ref_residual_mm_max']} mm")
    if fig["sim_multi_cam_status_cameras_moved"] != 0:
        fails.append("an unmoved camera was marked moved")
    assert not fails, "FAIL: " + "; ".join(fails)
    print("PASS")
