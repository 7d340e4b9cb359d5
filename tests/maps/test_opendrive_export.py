"""maps.opendrive_export: `tools/map export` of every shipped kit map writes OpenDRIVE 1.7 that
pyxodr reads, and `tools/map import --scale 1` of it gives back every lane: the same centre line
within 1 mm (each point of either within 1 mm of the other's line), the same half width, in the
same driving direction. Where lanes branch or merge (Tiny Town's crossings) the export has
junctions: connecting roads in them, a connection with a lane link for each lane into one, and
the re-imported routes walk only the kit's own successors."""

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
    # junctions: every lane pair where lanes branch or merge is a connection with a lane link
    # (to a road of its junction), and the imported routes walk only the kit's successors
    succ = exporter._successors(m)
    inner = exporter._junctions(succ)
    ids = {v: k for k, v in road_of.items()}
    conns = {(road_of[c.get("incomingRoad")], road_of[c.get("connectingRoad")])
             for j in root.findall("junction") for c in j.findall("connection")
             if c.find("laneLink") is not None}  # fmt: skip
    want = {(a, b) for a, bs in succ.items() for b in bs if b in inner and a not in inner}
    assert conns == want, name
    for b in inner:
        road = next(r for r in root.findall("road") if r.get("id") == ids[b])
        assert root.find(f"junction[@id='{road.get('junction')}']") is not None, b
    pairs = {(road_of[a.split("_")[0][1:]], road_of[b.split("_")[0][1:]])
             for r in doc["routes"] for a, b in zip(r["lanes"], r["lanes"][1:])}  # fmt: skip
    assert pairs <= {(a, b) for a, bs in succ.items() for b in bs}, name
    if name == "tiny_town":  # a map with 3- and 4-way crossings
        assert len(root.findall("junction")) >= 4 and want
