"""The missions' pose source and its report (autodrive.hil.pose_source), on synthetic poses (no
simulator: seconds): a planted EKF offset shows as the EKF error of that car only; Eye poses per
second of sim time; no EKF is given a start pose with an Eye; --eye none puts the car down off
its marked start; --city-eye is a deprecated alias of --eye; every mission defaults to the real
Eye, in lockstep with the simulator in a lockstep run."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from autodrive.hil import demo, pose_source
from autodrive.hil.missions import intersection


def _drive(rec: pose_source.PoseRecord, car: str, offset_m: float, eye_hz: float) -> None:
    """10 s of sim time along x at 0.2 m/s: truth at 100 Hz, the EKF offset_m off in y at
    100 Hz, Eye poses at eye_hz."""
    for k in range(1001):
        t = k * 0.01
        rec.on_truth(car, t, 0.2 * t, 0.0)
        rec.on_ekf(car, t + 0.005, 0.2 * (t + 0.005), offset_m)
        if eye_hz and k % round(100 / eye_hz) == 0:
            rec.on_eye(car, t)


def test_planted_ekf_error_and_eye_rate() -> None:
    rec = pose_source.PoseRecord()
    _drive(rec, "NIGEL1", 0.004, 5.0)
    _drive(rec, "NIGEL2", 0.05, 0.0)  # planted: 5 cm off, no Eye
    rep = pose_source.report("cameras", "test", [rec], ["NIGEL1", "NIGEL2", "NIGEL3"])
    assert rep["pose_source"] == "eye"
    assert rep["ekf_error_m"]["NIGEL1"]["p95"] == pytest.approx(0.004, abs=1e-4)
    assert rep["ekf_error_m"]["NIGEL2"]["max"] == pytest.approx(0.05, abs=1e-4)
    assert rep["ekf_error_m"]["NIGEL3"] is None  # never seen: said, not hidden
    assert rep["ekf_error_p95_worst_m"] == pytest.approx(0.05, abs=1e-4)
    assert rep["eye_poses_per_car_hz"]["NIGEL1"] == pytest.approx(5.0, abs=0.15)
    assert rep["eye_poses_per_car_hz"]["NIGEL2"] == 0.0
    assert rep["first_eye_fix_s"] == {"NIGEL1": 0.0}
    line = pose_source.summary_line(rep)
    assert "NIGEL2 p50 5.0" in line and "NIGEL3 no EKF map pose" in line, line


def test_ekf_never_starts_on_truth() -> None:
    start = (1.0, -2.0, 0.5)
    cfg: dict[str, dict[str, object]] = {"estimator": {"initial_pose_map": [9, 9, 9]}}
    pose_source.estimator_start(cfg, "cameras", start)
    assert "initial_pose_map" not in cfg["estimator"], "with an Eye: its first fix, nothing else"
    pose_source.estimator_start(cfg, "none", start)
    assert cfg["estimator"]["initial_pose_map"] == list(start)
    assert cfg["estimator"]["initial_pos_std_m"] == pose_source.PLACEMENT_STD_M
    placed = pose_source.placed([start], "none", 3)[0]
    off_m = math.hypot(placed[0] - start[0], placed[1] - start[1])
    assert 0 < off_m < 5 * pose_source.PLACEMENT_STD_M, placed
    assert pose_source.placed([start], "none", 3) == [placed], "seeded"
    assert pose_source.placed([start], "cameras", 3) == [start]


def test_one_eye_flag_default_cameras(capsys: pytest.CaptureFixture[str]) -> None:
    assert demo.parse_args(["--mission", "smart-city"]).eye == "cameras"
    assert demo.parse_args([]).eye == "cameras"
    assert intersection.parse_args([]).eye == "cameras"
    assert demo.parse_args(["--mission", "smart-city", "--city-eye", "standin"]).eye == "standin"
    assert "--city-eye is deprecated" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        demo.parse_args(["--city-eye", "standin", "--eye", "cameras"])
    assert "contradicts" in capsys.readouterr().err


def test_eye_lockstep_by_default_in_lockstep_runs(capsys: pytest.CaptureFixture[str]) -> None:
    """The real Eye in a lockstep run is in lockstep too (the sim's --eye-sync, the Eye's
    --sim-latency-ms L, L in the report); paced runs and the stand-in are not; a latency out of
    what autodrive-eye accepts is refused naming the option."""
    for args in (demo.parse_args(["--mission", "smart-city"]), intersection.parse_args([])):
        latency = pose_source.lockstep_latency_ms(args, lockstep=True)
        assert latency == pose_source.EYE_LATENCY_MS_DEFAULT
        assert "--eye-sync" in pose_source.sim_argv(args.eye, 5.0, latency)
        assert pose_source.eye_lockstep_argv(latency) == ["--sim-latency-ms", latency]
        assert pose_source.lockstep_latency_ms(args, lockstep=False) is None
    assert "--eye-sync" not in pose_source.sim_argv("cameras", 5.0, None)
    assert pose_source.eye_lockstep_argv(None) == []
    standin = demo.parse_args(["--eye", "standin"])
    assert pose_source.lockstep_latency_ms(standin, lockstep=True) is None
    given = intersection.parse_args(["--eye-latency-ms", "40"])
    assert pose_source.lockstep_latency_ms(given, lockstep=True) == 40.0
    rep = pose_source.report("cameras", "test", [pose_source.PoseRecord()], ["NIGEL1"], 40.0)
    assert rep["eye_latency_ms"] == 40.0
    for bad in ("-1", "20000", "fast"):
        with pytest.raises(SystemExit):
            demo.parse_args(["--eye-latency-ms", bad])
        assert "--eye-latency-ms" in capsys.readouterr().err


def test_eye_sync_give_ups_fail_the_report(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Planted: a sim log with two give-ups (its EYE_SYNC_GIVE_UP_MARK lines) fails a report
    that met its goals, naming the count and the option; a clean log and a run not in lockstep
    pass; an unreadable log is a failure, not a silent 0; the wait limit goes to the sim and a
    limit out of its range is refused naming the option. The real sim's lines: the test
    eye.Sim.GiveUpFailsTheReport."""
    log = tmp_path / "sim.log"
    mark = pose_source.EYE_SYNC_GIVE_UP_MARK
    log.write_text(f"[autodrive-sim] t = 1.0 s\n[autodrive-sim] {mark} (1): ...\nx {mark} (2)\n")
    assert pose_source.eye_sync_give_ups(log, 15.0) == 2
    assert pose_source.eye_sync_give_ups(log, None) is None, "not in lockstep: not counted"
    assert pose_source.eye_sync_give_ups(tmp_path / "missing.log", 15.0) == -1
    rep = pose_source.report("cameras", "t", [pose_source.PoseRecord()], ["NIGEL1"], 15.0, 2)
    assert rep["eye_sync_give_ups"] == 2
    rep["ok"] = True
    said: list[str] = []
    pose_source.eye_sync_verdict(rep, say=said.append)
    assert rep["ok"] is False
    assert rep["error"] == (
        "the Eye fell behind the sim 2 times: the run depended on wall time; rerun on a quieter "
        "machine or raise --eye-sync-wait-s"
    )
    assert said == [f"FAILED: {rep['error']}"]
    unknown = {"ok": True, "error": "timeout", "eye_sync_give_ups": -1}
    pose_source.eye_sync_verdict(unknown)
    assert unknown["ok"] is False and str(unknown["error"]).startswith("timeout; eye_sync_give")
    log.write_text("[autodrive-sim] t = 1.0 s\n")
    for give_ups in (pose_source.eye_sync_give_ups(log, 15.0), None):
        clean = {"ok": True, **pose_source.report("cameras", "t", [], [], 15.0, give_ups)}
        pose_source.eye_sync_verdict(clean)
        assert clean["ok"] is True and "error" not in clean
    assert pose_source.report("standin", "t", [], [], None, 3)["eye_sync_give_ups"] is None
    args = demo.parse_args(["--eye-sync-wait-s", "30"])
    argv = pose_source.sim_argv("cameras", 5.0, 15.0, args.eye_sync_wait_s)
    assert argv[-3:] == ["--eye-sync", "--eye-sync-wait-s", 30.0], argv
    assert intersection.parse_args([]).eye_sync_wait_s == pose_source.EYE_SYNC_WAIT_S_DEFAULT
    for bad in ("0", "4000", "long"):
        with pytest.raises(SystemExit):
            demo.parse_args(["--eye-sync-wait-s", bad])
        assert "--eye-sync-wait-s" in capsys.readouterr().err
