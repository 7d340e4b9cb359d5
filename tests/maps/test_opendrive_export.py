"""maps.opendrive_export: `tools/map export` of every shipped kit map writes OpenDRIVE 1.7 that
pyxodr reads, and `tools/map import --scale 1` of it gives back every lane: the same centre line
within 1 mm (each point of either within 1 mm of the other's line), the same half width, in the
same driving direction."""

from __future__ import annotations

import json
import math
import subprocess
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from autodrive.maps import geometry
from autodrive.maps.loader import load, names
from autodrive.maps.opendrive import exporter, importer, reference
from pyhelpers import REPO_ROOT

TOOL = REPO_ROOT / "tools" / "map"


def _gap_m(points: list[tuple[float, float]], line: list[tuple[float, float, float]]) -> float:
    return max(geometry.nearest_on_polyline(p, line)[0] for p in points)


WITH_LANES = [n for n in names() if load(n).lanes()]


def test_map_without_lanes_is_refused(tmp_path: Path) -> None:
    run = subprocess.run([str(TOOL), "export", "parking_school", "--xodr", str(tmp_path / "p.xodr")],
                         capture_output=True, text=True)  # fmt: skip
    assert run.returncode == 2 and "parking_school.yaml: no lanes" in run.stderr
    assert not (tmp_path / "p.xodr").exists()


@pytest.mark.parametrize("name", WITH_LANES)
def test_round_trip_within_1_mm(name: str, tmp_path: Path) -> None:
    xodr = tmp_path / f"{name}.xodr"
    run = subprocess.run(
        [str(TOOL), "export", name, "--xodr", str(xodr)], capture_output=True, text=True
    )
    assert run.returncode == 0, run.stderr
    root = ET.parse(xodr).getroot()
    assert (root.find("header").get("revMajor"), root.find("header").get("revMinor")) == ("1", "7")  # type: ignore[union-attr]
    road_of = {r.get("id"): r.get("name") for r in root.findall("road")}
    importer.write(xodr, 1.0, "rt", tmp_path / "rt")
    doc = json.loads((tmp_path / "rt" / "rt.json").read_text())
    ox, oy = doc["imported_from"]["offset_m"]
    m = load(name)
    back = {}
    for lane in doc["lanes"]:
        rid = lane["name"].split("_")[0][1:]
        back[road_of[rid]] = lane
    assert sorted(back) == sorted(ln.name for ln in m.lanes())
    for lane in m.lanes():
        ours = m.centre_line(lane, 0.05)
        theirs = [
            (p["x_m"] - ox, p["y_m"] - oy, p["heading_rad"]) for p in back[lane.name]["centre_line"]
        ]
        assert _gap_m([p[:2] for p in ours], theirs) < 0.001, lane.name
        assert _gap_m([p[:2] for p in theirs], ours) < 0.001, lane.name
        assert abs(math.remainder(ours[0][2] - theirs[0][2], 2 * math.pi)) < 0.01, lane.name
        assert back[lane.name]["half_width_m"] == pytest.approx(lane.half_width_m, abs=1e-6)
    assert reference.lane_lines(xodr)  # pyxodr reads the export
