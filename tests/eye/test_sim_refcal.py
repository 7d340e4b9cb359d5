"""eye.Sim.CamerasCalibrateFromReferenceTags: autodrive-sim --map tiny_town --eye renders the
town's overhead cameras and its reference tags (map description -> tools/gen-maps -> MJCF);
`autodrive-eye calibrate-map` calibrates every camera from the tags it sees, and reports how
each pair of neighbours agrees on the tags they share (autodrive.bench.eye_refcal)."""
from pathlib import Path

import pytest

from autodrive.bench import eye_refcal


def test_cameras_calibrate_from_reference_tags(build_dir: Path) -> None:
    try:
        fig = eye_refcal.measure(build_dir)
    except RuntimeError as e:
        pytest.fail(f"FAIL: {e}")
    print("\n".join(f"{k} {v:g}" for k, v in fig.items()))
    fails = []
    if fig["refcal_cameras"] != 4 or fig["refcal_tags_per_camera_min"] < 4:
        fails.append("not every camera was calibrated from its four reference tags")
    if fig["refcal_residual_rms_mm_max"] > 2.0:
        fails.append(f"reference tag residual {fig['refcal_residual_rms_mm_max']} mm rms > 2")
    # The pose is solved from four 25 px tags: the centre's error is mostly along the optical axis.
    if fig["refcal_camera_centre_error_mm_max"] > 30.0:
        fails.append(
            f"a camera centre {fig['refcal_camera_centre_error_mm_max']} mm from the map's"
        )
    if fig["refcal_overlap_pairs"] < 4:
        fails.append(f"only {fig['refcal_overlap_pairs']:g} of 4 neighbour pairs share a tag")
    if fig["refcal_overlap_agreement_rms_mm_max"] > 2.0:
        fails.append(f"cameras disagree by {fig['refcal_overlap_agreement_rms_mm_max']} mm rms")
    assert not fails, "FAIL: " + "; ".join(fails)
    print("PASS")
