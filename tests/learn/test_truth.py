"""The in-process world gives the ground truth of the pty HIL program: autodrive-sim (ptys
open, LIDAR on) with a scripted driver and a seed, against World.command + World.step with the
same commands and seed through the batch step, within 1 mm over 10 s of driving on a curve, at every 100 Hz truth
message."""

import os
import subprocess
import struct
import tempfile
from pathlib import Path

import numpy as np

from autodrive.core import lcmtypes
from autodrive.gym import World
from autodrive.gym import step_worlds

THROTTLE, STEERING, SEED, DURATION_S = 0.7, 0.4, 7, 10
TOLERANCE_M = 1e-3


def hil_truth(build: Path) -> list[tuple[int, np.ndarray]]:
    types = lcmtypes.load(build)
    with tempfile.TemporaryDirectory(prefix="learn-truth-") as d:
        log = os.path.join(d, "truth.bin")
        argv = [
            str(build / "bin" / "autodrive-sim"),
            "--quiet",
            "--lockstep",
            "--lcm-url",
            "memq://",
            "--run-dir",
            d,
            "--seed",
            str(SEED),
            "--duration",
            str(DURATION_S),
            "--script",
            f"constant:throttle={THROTTLE},steering={STEERING}",
            "--truth-log",
            log,
        ]
        subprocess.run(argv, check=True, capture_output=True)
        data = open(log, "rb").read()
    out, i = [], 0
    while i < len(data):
        (n,) = struct.unpack(">I", data[i : i + 4])
        m = types.ground_truth_t.decode(data[i + 4 : i + 4 + n])
        out.append((int(m.utime), np.asarray(m.position_m, dtype=np.float64)))
        i += 4 + n
    return out


def test_world_matches_hil_truth(build_dir: Path) -> None:
    truth = hil_truth(build_dir)
    assert len(truth) >= 100 * DURATION_S - 1, f"only {len(truth)} truth messages"
    w = World("parking_school", cars=1, seed=SEED, lidar_rays=360)
    w.command(0, THROTTLE, STEERING)
    worst = 0.0
    for utime, pos in truth:
        step_worlds([w], int(round(utime * 1e-3 - w.time_s * 1e3)))  # the batch API
        worst = max(worst, float(np.linalg.norm(w.observe(0).pos_m - pos)))
    travel = float(np.linalg.norm(truth[-1][1] - truth[0][1]))
    assert travel > 0.3, f"the car moved only {travel:.3f} m: nothing compared"
    assert worst < TOLERANCE_M, f"world vs HIL: {worst * 1e3:.3f} mm apart (limit 1 mm)"
    print(
        f"learn.truth: {len(truth)} messages over {DURATION_S} s, car {travel:.2f} m from its "
        f"start, largest difference {worst * 1e3:.6f} mm"
    )
