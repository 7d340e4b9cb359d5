"""autodrive.learn.sweep.parking --aggregate-only (tools/bench parking) on synthetic per-seed reports (no
demo runs): a good run, a run without report.json, a collision, a run whose demo exited non-zero
with an ok report; then ten good runs that meet every goal. Checks counts, medians/maxima, goals,
per-seed arrays, summary.json == the last stdout line, and that the plot is written."""
import json
import pathlib
import subprocess
import sys
import tempfile

GOALS = (
    "goal_all_success_no_collisions",
    "goal_final_pose",
    "goal_localization_rms",
    "goal_wall_s",
    "goals_met",
)


def report(pos_m, head_deg, loc_m, wall_s, collisions=0, success=True, clearance_m=0.3):
    return {
        "ok": success and collisions == 0,
        "success": success,
        "collisions": collisions,
        "final_pos_error_m": pos_m,
        "final_heading_error_deg": head_deg,
        "localization_rms_m": loc_m,
        "wall_s": wall_s,
        "sim_s": 2 * wall_s,
        "min_clearance_m": clearance_m,
        "path_length_m": 0.93,
        "slot": 2,
        "start_world": [-1.0, 0.6, 0.0],
        "goal_world": [-0.45, 1.1792, 1.5708],
    }


def put(out, seed, rep=None, exit_code=None, gt=True):
    d = out / f"seed{seed}"
    d.mkdir(parents=True)
    if rep is not None:
        (d / "report.json").write_text(json.dumps(rep))
    if exit_code is not None:
        (d / "demo_exit_code").write_text(f"{exit_code}\n")
    if gt:
        (d / "gt.csv").write_text("x_m,y_m,yaw_rad\n0,0,0\n0.3,0.1,0.5\n0.55,0.58,1.57\n")


def sweep(out, seeds, first=1):
    r = subprocess.run(
        [
            sys.executable,
            "-m",
            "autodrive.learn.sweep.parking",
            "--aggregate-only",
            "--first-seed",
            str(first),
            "--seeds",
            str(seeds),
            "--out",
            str(out),
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert r.returncode == 0, f"sweep exited {r.returncode}: {r.stderr}"
    last = json.loads(r.stdout.strip().splitlines()[-1])
    assert last == json.loads((out / "summary.json").read_text()), "stdout JSON != summary.json"
    assert (out / "parking_sweep.png").stat().st_size > 5000, "plot missing or empty"
    assert not list(out.glob("*.tmp")), "temporary file left behind"
    return last, r.stderr


def test_aggregate_of_synthetic_reports() -> None:
    with tempfile.TemporaryDirectory(prefix="parking-sweep-") as tmp:
        mixed = pathlib.Path(tmp) / "mixed"
        put(mixed, 1, report(0.010, 1.0, 0.020, 8.0), exit_code=0)
        put(mixed, 2, None, exit_code=1, gt=False)  # demo died: no report
        put(mixed, 3, report(0.050, 3.0, 0.040, 9.0, collisions=2, clearance_m=0.0), exit_code=1)
        put(mixed, 4, report(0.012, 0.5, 0.025, 130.0), exit_code=1)  # ok report, exit 1
        s, err = sweep(mixed, 4)
        print(err)
        assert s["runs"] == 4 and s["reports"] == 3, s
        assert s["successes"] == 1, "only seed 1 is ok (seed 4's demo exited 1)"
        assert s["collisions_total"] == 2
        assert s["final_pos_error_m_median"] == 0.012 and s["final_pos_error_m_max"] == 0.05
        assert (
            s["final_heading_error_deg_max"] == 3.0 and s["final_heading_error_deg_median"] == 1.0
        )
        assert s["localization_rms_m_max"] == 0.04 and s["wall_s_max"] == 130.0
        assert s["min_clearance_m_min"] == 0.0
        assert s["per_seed"]["seed"] == [1, 2, 3, 4]
        assert s["per_seed"]["ok"] == [True, False, False, False]
        assert s["per_seed"]["final_pos_error_m"] == [0.01, None, 0.05, 0.012]
        assert s["per_seed"]["error"][1] == "no report.json, demo exit 1"
        assert s["per_seed"]["error"][2] == "2 collision(s), demo exit 1"
        assert s["per_seed"]["error"][3] == "demo exit 1"
        for goal in GOALS:
            assert s[goal] is False, goal
        assert "[parking 2/4] seed 2: FAILED (no report.json, demo exit 1)\n" in err, err

        good = pathlib.Path(tmp) / "good"
        for seed in range(5, 15):
            put(good, seed, report(0.005 + 0.001 * seed, 1.5, 0.02, 9.0), exit_code=0)
        s, _ = sweep(good, 10, first=5)
        assert s["runs"] == 10 and s["successes"] == 10 and s["collisions_total"] == 0, s
        assert s["final_pos_error_m_max"] == 0.019 and s["final_pos_error_m_median"] == 0.0145
        for goal in GOALS:
            assert s[goal] is True, goal
        s, _ = sweep(good, 2, first=5)  # the first two of them: every goal but the ten runs
        assert s["goal_final_pose"] is True and s["goals_met"] is False, "2 runs cannot meet 10/10"

        bad = subprocess.run(
            [sys.executable, "-m", "autodrive.learn.sweep.parking", "--seeds", "0"],
            capture_output=True,
            text=True,
            timeout=60,
        )
        assert bad.returncode == 2 and "--seeds 0" in bad.stderr, bad.stderr
    print("parking sweep aggregate ok")
