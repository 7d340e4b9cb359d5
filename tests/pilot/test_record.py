"""tools/pilot record on a short real run: the simulator's expert (pure pursuit on Driving
School's loop_ccw with seeded perturbations, front camera at 10 Hz) recorded by lcm-logger over
UDP multicast; the dataset's manifest and table must match the log frame for frame, labels from
the ground truth sample at or before each frame. make-model --other-lane-laps drives the road's
other lane in loop_ccw's direction (never the clockwise loop_cw, an unseen test condition): the
car keeps one lane width left of loop_ccw's centre line. A log without camera
frames is refused, and the message names the log."""

from __future__ import annotations

import bisect
import csv
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import cv2

sys.path.insert(0, str(Path(__file__).parent))
import gen_log  # noqa: E402

from autodrive.core import channels  # noqa: E402
from autodrive.core import lcmtypes  # noqa: E402
from autodrive import maps  # noqa: E402
from autodrive.hil.missions.lane_watch import LaneWatch  # noqa: E402
from autodrive.learn.pilot.make_model import expert_runs  # noqa: E402
from autodrive.learn.pilot.dataset import record  # noqa: E402
from autodrive.learn.pilot.expert import ExpertRun, record_expert  # noqa: E402

SEED = 3


def check_real_run(d: Path, build: Path) -> None:
    log = d / "expert.lcmlog"
    run = ExpertRun(laps=1, seed=SEED, perturb=0.5, camera_fps=10.0, duration_s=4.0)
    record_expert(run, log, build)
    manifest = record([log], d / "ds", build=build, progress=False)
    t = lcmtypes.load(build)
    cam, gt = channels.channel("CAM_FRONT", "NIGEL1"), channels.channel("GROUND_TRUTH", "NIGEL1")
    frames, truth = [], []
    for e in lcmtypes.events(log):
        if e.channel == cam:
            frames.append(t.compressed_image_t.decode(e.data).utime)
        elif e.channel == gt:
            m = t.ground_truth_t.decode(e.data)
            truth.append((m.utime, m.command_steering, m.expert_steering))
    truth.sort()
    frames.sort()
    stamps = [u for u, _, _ in truth]
    labelled = [u for u in frames if bisect.bisect_right(stamps, u) > 0]
    assert len(frames) >= 30, f"4 s at 10 Hz gave only {len(frames)} frames"
    assert manifest["frame_count"] == len(labelled), (manifest["frame_count"], len(labelled))
    assert manifest["map"] == "driving_school" and manifest["seed"] == SEED, manifest
    assert manifest["source_logs"][0]["log"] == str(log)
    assert manifest["source_logs"][0]["meta"]["route"] == "loop_ccw"
    assert sum(manifest["frames_per_lap"].values()) == len(labelled)
    assert manifest["camera"]["fx_px"] > 0
    with open(d / "ds" / "frames.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert [int(r["utime_us"]) for r in rows] == labelled
    perturbed = 0
    for r in rows:
        u, cmd, expert = truth[bisect.bisect_right(stamps, int(r["utime_us"])) - 1]
        assert abs(float(r["command_steering"]) - cmd) < 1e-4, r
        assert abs(float(r["steering"]) - expert) < 1e-4, r  # the label is the expert's
        assert r["lap"] == "0"
        perturbed += int(r["perturbed"])
        if r["perturbed"] == "1":
            assert abs(cmd - expert) > 0.1, r  # a perturbation of at least A/2
    assert perturbed >= 2, f"no perturbation in 4 s ({perturbed} frames)"
    img = cv2.imread(str(d / "ds" / rows[-1]["file"]))
    assert img is not None and img.shape == (480, 640, 3)
    print(f"real run: {len(rows)} frames, {perturbed} perturbed, manifest ok")


def check_other_lane(d: Path, build: Path) -> None:
    assert {r.lane_shift for r in expert_runs(5, SEED)} == {0}  # the shipped recipe: one lane
    runs = expert_runs(5, SEED, other_lane_laps=2)
    assert sum(r.laps for r in runs) == 5 and runs[0].laps == 2, runs
    assert {r.route for r in runs} == {ExpertRun.route}, runs  # one direction only
    assert sorted(r.lane_shift for r in runs) == [0, 1], runs  # both lanes of the road
    log = d / "other_lane.lcmlog"
    run = ExpertRun(laps=1, seed=SEED, perturb=0.0, camera_fps=5.0, duration_s=4.0,
                    lane_shift=max(r.lane_shift for r in runs))  # fmt: skip
    record_expert(run, log, build)
    record([log], d / "ds_other", build=build, progress=False)
    route = maps.load(run.map).route(run.route)
    watch = LaneWatch(route, [])
    with open(d / "ds_other" / "frames.csv", newline="") as fh:
        rows = [r for r in csv.DictReader(fh) if r["x_m"] and float(r["speed_m_s"] or 0) > 0.05]
    assert len(rows) >= 10, f"only {len(rows)} frames of a moving car"
    offsets = [watch.locate(float(r["x_m"]), float(r["y_m"]))[0] for r in rows]
    lane_m = 2 * route.half_width_m  # adjacent lanes: centre to centre
    worst = max(abs(o - lane_m) for o in offsets)
    assert worst < 0.3 * route.half_width_m, (worst, offsets)  # left of the route, in its lane
    print(
        f"other lane: {len(rows)} frames, offset from loop_ccw {min(offsets):.3f}..."
        f"{max(offsets):.3f} m (one lane {lane_m:.2f} m)"
    )


def check_refusal(d: Path, build: Path) -> None:
    log = d / "no_camera.lcmlog"
    assert gen_log.write(log, build, laps=1, frames_per_lap=20, cameras=False) == 0
    out = d / "refused"
    r = subprocess.run(
        [sys.executable, "-m", "autodrive.learn.pilot", "record", str(log), "--out", str(out),
         "--map", "driving_school"],
        capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    assert r.returncode == 1, (r.returncode, r.stderr)
    assert str(log) in r.stderr and "no camera frames" in r.stderr, r.stderr
    assert not (out / "manifest.json").exists()
    print(f"refused: {r.stderr.strip()}")


def test_record_real_run_and_refusal(build_dir: Path) -> None:
    build = build_dir
    with tempfile.TemporaryDirectory(prefix="pilot-record-") as tmp:
        check_refusal(Path(tmp), build)
        check_real_run(Path(tmp), build)
        check_other_lane(Path(tmp), build)
