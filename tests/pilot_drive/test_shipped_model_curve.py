"""The shipped pilot model (models/pilot/driving_school.onnx) drives Driving School's first curve
in HIL: tools/demo --mission cloning (autodrive-sim in lockstep with the unchanged
autodrive-runtime on its Nano pty, autodrive-pilot on the rendered front camera, real LCM on the
test's UDP port) from 0.5 m before the curve of loop_ccw (s = 6.0-7.3 m, a quarter turn of
0.76 m radius) to 0.9 m after it. Judged by the mission's referee on ground truth and sim time:
the distance driven along the route, no wheel over the lane bound and no stall (no
intervention), every process ending cleanly (exit codes, sanitizer reports)."""

import json
import subprocess
import sys
import tempfile
from pathlib import Path

START_M = 5.5  # along loop_ccw [m]: 0.5 m before the curve
DISTANCE_M = 2.7  # [m]: through the curve (1.3 m) and 0.9 m beyond
CROSS_TRACK_RMS_MAX_M = 0.05  # of the lane's 0.14 m half width
HANG_BACKSTOP_S = 900.0  # wall time [s]: ends a hung run only, never a figure


def test_shipped_model_drives_a_curve(root: Path, build_dir: Path, lcm_url: str) -> None:
    model = root / "models" / "pilot" / "driving_school.onnx"
    with tempfile.TemporaryDirectory(prefix="pilot-curve-") as tmp:
        out = Path(tmp) / "run"
        run = subprocess.run(
            [sys.executable, "-m", "autodrive.hil.demo", "--mission", "cloning"]
            + ["--build", str(build_dir), "--out", str(out), "--headless", "--lcm-url", lcm_url]
            + ["--model", str(model), "--start-m", str(START_M), "--distance-m", str(DISTANCE_M)]
            + ["--timeout", str(HANG_BACKSTOP_S)],
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
            timeout=HANG_BACKSTOP_S + 120,
        )
        print(run.stdout[-3000:])
        rep = json.loads((out / "report.json").read_text())
    assert rep["model"].endswith("driving_school.onnx"), rep
    assert rep["distance_m"] >= DISTANCE_M and rep["ok"], rep
    assert rep["interventions"] == 0 and rep["stalls"] == 0, rep
    assert rep["cross_track_rms_m"] <= CROSS_TRACK_RMS_MAX_M, rep
    assert rep["frames"] > 0 and not rep.get("sanitizer_reports"), rep
    assert run.returncode == 0, (run.returncode, rep)
    print(
        f"shipped model through the curve: {rep['distance_m']} m in {rep['elapsed_sim_s']} s of "
        f"sim time, cross-track rms {rep['cross_track_rms_m']} m, no intervention"
    )
