"""maps.opendrive_export: `tools/map export` of every shipped kit map writes OpenDRIVE 1.7 that
pyxodr reads, and `tools/map import --scale 1` of it gives back every lane: the same centre line
within 1 mm (each point of either within 1 mm of the other's line), the same half width, in the
same driving direction. Where lanes branch or merge (Tiny Town's crossings) the export has
junctions: connecting roads in them, a connection with a lane link for each lane into one, and
the re-imported routes walk only the kit's own successors. An imported map's markings come
back as road marks of their lanes."""

from __future__ import annotations

import json
import math
import subprocess
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from autodrive.maps import geometry
from autodrive.maps.loader import load, names
from autodrive.maps.opendrive import exporter, fixtures, importer, reference
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


def test_markings_round_trip(tmp_path: Path) -> None:
    """An imported map with road marks (scenariogeneration's crossing: solid white edges, broken
    and solid yellow centre lines) exported and imported again at --scale 1: each marking comes
    back on the same lane and side, of the same kind, colour, width and dash; solid strokes
    within 1 mm of the first import's, broken ones' dashes within 1 mm of the lane border they
    paint (the dashes are laid along the exported road's reference line, the lane's centre, so
    on curves they shift along the line: their count is kept within one)."""
    xodr = fixtures.crossing(tmp_path / "crossing.xodr")
    importer.write(xodr, 1 / 14, "a", tmp_path / "a")
    a = load(tmp_path / "a" / "a.yaml")
    run = subprocess.run([str(TOOL), "export", str(tmp_path / "a" / "a.yaml"), "--xodr",
                          str(tmp_path / "a.xodr")], capture_output=True, text=True)  # fmt: skip
    assert run.returncode == 0, run.stderr
    road_of = {
        r.get("id"): r.get("name") for r in ET.parse(tmp_path / "a.xodr").getroot().findall("road")
    }
    importer.write(tmp_path / "a.xodr", 1.0, "b", tmp_path / "b")
    b = load(tmp_path / "b" / "b.yaml")
    assert b.imported_from is not None
    ox, oy = b.imported_from.offset_m
    back = {}
    for mk in b.markings:
        assert mk.lane is not None
        lane = road_of[mk.lane.split("_")[0][1:]]
        back.setdefault((lane, mk.side), []).append(mk)
    owned = [mk for mk in a.markings if mk.lane is not None]
    assert owned and len(owned) == len(b.markings)
    for mk in owned:
        (got,) = back[(mk.lane, mk.side)]
        assert (got.kind, got.colour) == (mk.kind, mk.colour), mk.name
        assert got.width_m == pytest.approx(mk.width_m, abs=1e-9)
        assert got.dash_m == (None if mk.dash_m is None else pytest.approx(mk.dash_m, abs=1e-9))
        lane = a.lane(mk.lane)
        d = (lane.half_width_m if mk.side == "left" else -lane.half_width_m) + mk.offset_m
        border = [
            (x - d * math.sin(h), y + d * math.cos(h), h) for x, y, h in a.centre_line(lane, 0.01)
        ]
        ours = [p for st in mk.strokes for p in st]
        theirs = [(x - ox, y - oy) for st in got.strokes for x, y in st]
        assert _gap_m(theirs, border) < 0.001 and _gap_m(ours, border) < 0.001, mk.name
        if mk.kind == "solid":
            line = [(x, y, 0.0) for x, y in mk.strokes[0]]
            assert _gap_m(theirs, line) < 0.001, mk.name
        assert abs(len(got.strokes) - len(mk.strokes)) <= 1, mk.name
