"""maps.opendrive_drive: an imported OpenDRIVE network (scenariogeneration's crossing, 1:14) loads
in the simulator's library (real MuJoCo, the emulated Nano: autodrive.gym.World), steps, and a
car steered by the shared pure pursuit (the simulator's route driver's rule) drives a generated
route through the junction to its end without the simulator ever finding it off its lane or
in a collision."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

from autodrive.gym import World
from autodrive.maps.opendrive import drive, fixtures
from pyhelpers import REPO_ROOT

TOOL = REPO_ROOT / "tools" / "map"
ROUTE = "r1r1_to_r3r1"  # through the junction, straight on, past light 1


def test_imported_map_loads_steps_and_is_driven(tmp_path: Path) -> None:
    xodr = fixtures.crossing(tmp_path / "crossing.xodr")
    run = subprocess.run([str(TOOL), "import", str(xodr), "--name", "crossing", "--out", str(tmp_path)],
                         capture_output=True, text=True)  # fmt: skip
    assert run.returncode == 0, run.stderr
    doc = json.loads((tmp_path / "crossing.json").read_text())
    world = World(str(tmp_path / "crossing.xml"), cars=1)
    world.reset(0)
    world.step(100)
    assert abs(world.time_s - 0.1) < 1e-9
    world.close()
    route = next(r for r in doc["routes"] if r["name"] == ROUTE)
    done = drive.drive(tmp_path / "crossing.xml", ROUTE, [tuple(p) for p in route["polyline_m"]])
    print(done)
    assert done.reached_end and done.off_lane_steps == 0 and done.collisions == 0, done
    assert done.max_lateral_m < done.half_width_m / 2


def test_drive_scorer_sees_a_planted_lane_departure(tmp_path: Path) -> None:
    """The car steered along the route moved 0.2 m to its right: the simulator's lane test
    (against the true route) must find it off its lane, and the drive must not be ok."""
    xodr = fixtures.crossing(tmp_path / "crossing.xodr")
    subprocess.run([str(TOOL), "import", str(xodr), "--name", "crossing", "--out", str(tmp_path)],
                   check=True, capture_output=True)  # fmt: skip
    doc = json.loads((tmp_path / "crossing.json").read_text())
    route = next(r for r in doc["routes"] if r["name"] == ROUTE)
    pts = [tuple(p) for p in route["polyline_m"]]
    shifted = []
    for (x0, y0), (x1, y1) in zip(pts, pts[1:] + [pts[-1]]):
        if (x0, y0) == (x1, y1):
            shifted.append(shifted[-1])
            continue
        d = ((x1 - x0) ** 2 + (y1 - y0) ** 2) ** 0.5
        shifted.append((x0 + 0.2 * (y1 - y0) / d, y0 - 0.2 * (x1 - x0) / d))
    done = drive.drive(tmp_path / "crossing.xml", ROUTE, shifted, max_sim_s=20.0)
    assert done.off_lane_steps > 0 and not done.ok, done
