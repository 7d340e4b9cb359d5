"""runtime.replay.ekf: a recorded HIL run (STATE, IMU and Eye poses of NIGEL1, in
tests/replay/data/ekf_input.lcmlog) fed through file:// into the runtime's estimator
(autodrive-replay) gives the stored reference outputs (ekf_reference.json: every ODOM and
POSE_MAP message's stamp, and every 10th one's pose and speed) within 1e-6 m / 1e-6 rad /
1e-6 m/s, and two replays give the same log.

`.venv/bin/python -m pytest test_replay_ekf.py --build-dir BUILD --update-reference` rewrites the
reference from that build: only when the estimator changed on purpose; say so in the commit."""

from __future__ import annotations

import json
import pathlib
import subprocess
import sys
import tempfile
from typing import Any

import pytest
import yaml
from pyhelpers import REPO_ROOT

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "python"))
from autodrive.core import lcmtypes  # noqa: E402
from autodrive.core.channels import channel  # noqa: E402


def test_replay_gives_reference(build_dir: pathlib.Path, pytestconfig: pytest.Config) -> None:
    root, build = REPO_ROOT, build_dir
    DATA = root / "tests" / "replay" / "data"
    INPUT, REFERENCE = DATA / "ekf_input.lcmlog", DATA / "ekf_reference.json"
    CONFIG = root / "runtime" / "jetson" / "config" / "nigel_hil.yaml"
    VEHICLE, EVERY = "NIGEL1", 10
    TOL_M, TOL_RAD, TOL_M_S = 1e-6, 1e-6, 1e-6

    def replay(out: pathlib.Path, config: pathlib.Path = CONFIG) -> dict[str, Any]:
        r = subprocess.run(
            [str(build / "bin" / "autodrive-replay"), "-c", str(config)]
            + ["--in", str(INPUT), "--out", str(out)],
            capture_output=True,
            text=True,
            timeout=120,
        )
        assert r.returncode == 0, f"autodrive-replay failed: {r.stdout}{r.stderr}"
        print(r.stdout.strip())
        types = lcmtypes.load(build)
        series: dict[str, Any] = {}
        for ev in lcmtypes.events(out):
            m = types.odometry_t.decode(ev.data)
            series.setdefault(str(ev.channel), []).append(
                [m.utime, m.x_m, m.y_m, m.yaw_rad, m.vx_m_s]
            )
        return {
            name: {"stamps_us": [s[0] for s in rows], "samples": rows[::EVERY]}
            for name, rows in series.items()
        }

    with tempfile.TemporaryDirectory(prefix="replay-ekf-") as tmp:
        first = replay(pathlib.Path(tmp) / "a.lcmlog")
        second = replay(pathlib.Path(tmp) / "b.lcmlog")
        # The comparison can fail: the same log through an estimator that trusts the wheels 4x less.
        cfg = yaml.safe_load(CONFIG.read_text())
        cfg["estimator"]["odom_speed_std_m_s"] *= 4
        detuned_config = pathlib.Path(tmp) / "detuned.yaml"
        detuned_config.write_text(yaml.safe_dump(cfg))
        detuned = replay(pathlib.Path(tmp) / "c.lcmlog", detuned_config)
        if pytestconfig.getoption("update_reference"):
            REFERENCE.write_text(json.dumps(first, indent=0) + "\n")
            print(f"wrote {REFERENCE}")
            return

    assert first == second, "two replays of the same log differ"
    pose_map = channel("POSE_MAP", VEHICLE)
    assert detuned[pose_map]["samples"] != first[pose_map]["samples"], "a detuned EKF gave the same"
    for name in (channel("ODOM", VEHICLE), channel("POSE_MAP", VEHICLE)):
        assert name in first and len(first[name]["stamps_us"]) > 100, f"too few {name} outputs"
    reference = json.loads(REFERENCE.read_text())
    problems = []
    for name, want in reference.items():
        got = first.get(name, {"stamps_us": [], "samples": []})
        if got["stamps_us"] != want["stamps_us"]:
            problems.append(
                f"{name}: {len(got['stamps_us'])} messages, reference {len(want['stamps_us'])}, "
                "or their stamps differ"
            )
            continue
        worst = [0.0, 0.0, 0.0]
        for g, w in zip(got["samples"], want["samples"]):
            worst[0] = max(worst[0], abs(g[1] - w[1]), abs(g[2] - w[2]))
            worst[1] = max(worst[1], abs(g[3] - w[3]))
            worst[2] = max(worst[2], abs(g[4] - w[4]))
        print(
            f"{name}: {len(got['stamps_us'])} messages; worst difference {worst[0]:.2e} m, "
            f"{worst[1]:.2e} rad, {worst[2]:.2e} m/s"
        )
        if worst[0] > TOL_M or worst[1] > TOL_RAD or worst[2] > TOL_M_S:
            problems.append(f"{name}: off the reference by {worst}")
    assert not problems, "\n".join(problems)
    print("replay ekf ok")
