"""runtime.replay.amcl: 8 s of a parking run's <VEH>_LIDAR and <VEH>_ODOM
(tests/replay/data/amcl_input.lcmlog), fed through file:// into autodrive-autonomy localising
on the run's saved map, give the stored reference POSE_AMCL (amcl_reference.json: every stamp
and pose) within 1e-6 m / 1e-6 rad; two replays agree; and the replay stays within 3 cm of what
the live run estimated at the same stamps (amcl_live.json). The fixture comes from
make_amcl_fixture.py.

`.venv/bin/python -m pytest test_replay_amcl.py --build-dir BUILD --update-reference` rewrites the
reference from that build: only when the localisation changed on purpose; say so in the commit."""

from __future__ import annotations

import json
import math
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
    REFERENCE = DATA / "amcl_reference.json"
    VEHICLE = "NIGEL1"
    TOL_M, TOL_RAD, LIVE_TOL_M = 1e-6, 1e-6, 0.03

    def replay(tmp: pathlib.Path, name: str) -> list[list[float]]:
        config = yaml.safe_load((DATA / "amcl_autonomy.yaml").read_text())
        config["map"]["load_from"] = str(DATA / config["map"]["load_from"])
        config["out_dir"] = str(tmp / name)
        config_path = tmp / f"{name}.yaml"
        config_path.write_text(yaml.safe_dump(config))
        out = tmp / f"{name}.lcmlog"
        r = subprocess.run(
            [str(build / "bin" / "autodrive-autonomy"), "--config", str(config_path)]
            + ["--replay", str(DATA / "amcl_input.lcmlog"), "--replay-out", str(out)],
            capture_output=True,
            text=True,
            timeout=300,
        )
        assert r.returncode == 0, f"autodrive-autonomy --replay failed: {r.stdout}{r.stderr}"
        types = lcmtypes.load(build)
        poses = []
        for ev in lcmtypes.events(out):
            if ev.channel == channel("POSE_AMCL", VEHICLE):
                p = types.pose2d_t.decode(ev.data)
                poses.append([p.utime, p.x_m, p.y_m, p.yaw_rad])
        return poses

    with tempfile.TemporaryDirectory(prefix="replay-amcl-") as tmp:
        first = replay(pathlib.Path(tmp), "a")
        second = replay(pathlib.Path(tmp), "b")
    if pytestconfig.getoption("update_reference"):
        REFERENCE.write_text(json.dumps({"pose_amcl": first}, indent=0) + "\n")
        print(f"wrote {REFERENCE}: {len(first)} poses")
        return

    assert first == second, "two replays of the same log differ"
    assert len(first) >= 20, f"only {len(first)} AMCL poses from 8 s of scans"
    want: list[Any] = json.loads(REFERENCE.read_text())["pose_amcl"]
    assert [p[0] for p in first] == [
        p[0] for p in want
    ], f"{len(first)} AMCL poses, reference {len(want)}, or their stamps differ"
    worst_m = max(math.hypot(g[1] - w[1], g[2] - w[2]) for g, w in zip(first, want))
    worst_rad = max(abs(math.remainder(g[3] - w[3], math.tau)) for g, w in zip(first, want))
    print(
        f"{len(first)} AMCL poses; worst difference to the reference {worst_m:.2e} m, "
        f"{worst_rad:.2e} rad"
    )
    assert worst_m <= TOL_M and worst_rad <= TOL_RAD, "off the reference"

    live = {p[0]: p for p in json.loads((DATA / "amcl_live.json").read_text())["live_amcl"]}
    common = [(g, live[g[0]]) for g in first if g[0] in live]
    assert len(common) >= 10, f"only {len(common)} stamps shared with the live run"
    worst_live = max(math.hypot(g[1] - w[1], g[2] - w[2]) for g, w in common[len(common) // 4 :])
    print(
        f"vs the live run at {len(common)} shared stamps (after the first quarter): worst "
        f"{worst_live * 100:.2f} cm"
    )
    assert worst_live <= LIVE_TOL_M, "the replay strays from what the live run estimated"
    print("replay amcl ok")
