"""maps.opendrive_import: `tools/map import` on OpenDRIVE networks that scenariogeneration writes
in the test (autodrive.maps.opendrive.fixtures): a 4-way junction of line, spiral, arc and both
kinds of paramPoly3 roads with lights, signs, an unknown signal and a slope; a road of three lane
sections with a lane offset, a poly3 geometry and a border record. The maps load and check, the
sidecar's centre lines lie within 10 mm (full scale) of pyxodr's, routes are walked through the
junction, signals become lights with stop lines and signs, the unknown one is listed, the slope
is flattened with a warning naming the road, imported_from maps the file's points to ours, and
the road marks (solid, broken, white, yellow) become markings on pyxodr's lane borders."""

from __future__ import annotations

import json
import math
import re
import subprocess
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
import yaml

from autodrive.maps import eye_cameras
from autodrive.maps.opendrive import city_drive, fixtures, reference
from pyhelpers import REPO_ROOT

TOOL = REPO_ROOT / "tools" / "map"


@pytest.fixture(scope="module")
def imported(tmp_path_factory: pytest.TempPathFactory) -> dict[str, tuple[Path, dict, str]]:
    folder = tmp_path_factory.mktemp("xodr")
    out = {}
    for name, path in fixtures.write_all(folder).items():
        run = subprocess.run([str(TOOL), "import", str(path), "--scale", "1:14", "--name", name,
                              "--out", str(folder / "maps")], capture_output=True, text=True)  # fmt: skip
        assert run.returncode == 0, run.stderr
        out[name] = (path, json.loads((folder / "maps" / f"{name}.json").read_text()), run.stderr)
    return out


def test_lanes_match_pyxodr(imported: dict[str, tuple[Path, dict, str]]) -> None:
    for name, (path, doc, _) in imported.items():
        dev_mm = reference.max_centre_deviation_m(path, doc) * 1000
        assert dev_mm <= 10.0, f"{name}: {dev_mm:.2f} mm"


def test_crossing_routes_signals_and_warnings(imported: dict[str, tuple[Path, dict, str]]) -> None:
    path, doc, stderr = imported["crossing"]
    names = {r["name"] for r in doc["routes"]}
    # every approach turns into the three other roads
    assert {"r1r1_to_r2r1", "r1r1_to_r3r1", "r1r1_to_r4l1", "r4r1_to_r1l1"} <= names
    r = next(r for r in doc["routes"] if r["name"] == "r1r1_to_r3r1")
    assert r["lanes"][0].startswith("r1_") and r["lanes"][-1].startswith("r3_")
    assert any(lane.startswith("r1") and lane[2:3] != "_" for lane in r["lanes"][1:-1])  # conn.
    assert len(doc["traffic_lights"]) == 3 and len(doc["stop_lines"]) == 3
    # signal 6 (light 3, road 4) crosses the opposite approaches of signals 1 and 2 (lights 1, 2)
    assert doc["imported_from"]["signal_lights"] == {"1": [1], "2": [2], "6": [3]}
    assert doc["light_conflicts"] == [[1, 3], [2, 3]]
    assert {s["kind"] for s in doc["signs"]} == {"stop", "speed_limit"}
    limit = next(s for s in doc["signs"] if s["kind"] == "speed_limit")
    assert limit["speed_limit_m_s"] == pytest.approx(50 / 3.6 / 14, abs=1e-6)
    imp = doc["imported_from"]
    assert imp["file"] == "crossing.xodr" and imp["scale"] == pytest.approx(1 / 14)
    assert any("signal '5' on road '4' (type 138" in u for u in imp["unsupported_signals"])
    assert "road '4': elevation flattened" in stderr
    assert "road '4': elevation flattened" in " ".join(imp["warnings"])


def test_imported_from_maps_file_points_to_ours(
    imported: dict[str, tuple[Path, dict, str]]
) -> None:
    path, doc, _ = imported["sections"]
    imp = doc["imported_from"]
    lane = next(ln for ln in doc["lanes"] if ln["name"] == "r1_s0_r1")
    ref = reference.lane_lines(path)[("1", 0, -1)]  # pyxodr, the file's frame
    x, y = ref[0]
    p = lane["centre_line"][0]
    assert p["x_m"] == pytest.approx(imp["scale"] * x + imp["offset_m"][0], abs=1e-4)
    assert p["y_m"] == pytest.approx(imp["scale"] * y + imp["offset_m"][1], abs=1e-4)
    assert len({ln["name"].split("_")[1] for ln in doc["lanes"]}) == 3  # three lane sections
    assert any("opens or closes" in w for w in imp["warnings"])


def test_deviation_scorer_sees_a_planted_gap(imported: dict[str, tuple[Path, dict, str]]) -> None:
    path, doc, _ = imported["crossing"]
    bad = json.loads(json.dumps(doc))
    p = bad["lanes"][3]["centre_line"][5]
    shift = 0.02 * doc["imported_from"]["scale"]  # 20 mm at full scale, across the lane
    p["x_m"] -= shift * math.sin(p["heading_rad"])
    p["y_m"] += shift * math.cos(p["heading_rad"])
    assert reference.max_centre_deviation_m(path, bad) * 1000 > 15.0


def test_crossing_lights_of_one_controller_get_their_own_phases(tmp_path: Path) -> None:
    """A controller planted into the file for signals 1 and 6, whose approaches cross: the
    importer does not let them show green together (light 3 gets its own phase, with a warning
    naming the controller), and the programs pass the map's conflict check."""
    path = fixtures.crossing(tmp_path / "crossing.xodr")
    tree = ET.parse(path)
    root = tree.getroot()
    ctl = ET.SubElement(root, "controller", {"id": "c1", "name": "both"})
    for rid in ("1", "4"):  # scenariogeneration numbers signals on anew in a second network
        road = next(r for r in root.findall("road") if r.get("id") == rid)
        sig = next(g for g in road.iter("signal") if g.get("type") == "1000001")
        ET.SubElement(ctl, "control", {"signalId": str(sig.get("id"))})
    tree.write(path)
    run = subprocess.run([str(TOOL), "import", str(path), "--name", "ctl", "--out",
                          str(tmp_path / "maps")], capture_output=True, text=True)  # fmt: skip
    assert run.returncode == 0, run.stderr
    assert "controller 'c1': lights 1 and 3 cross at junction '100'" in run.stderr
    doc = json.loads((tmp_path / "maps" / "ctl.json").read_text())
    progs = {t["id"]: t["program"] for t in doc["traffic_lights"]}
    assert progs[1]["offset_s"] != progs[3]["offset_s"] and [1, 3] in doc["light_conflicts"]


def test_map_check_refuses_overlapping_greens_of_crossing_lights(tmp_path: Path) -> None:
    """The planted fault: the imported description edited so that light 3 (crossing light 1)
    runs light 1's program. The map's check refuses it, naming the lights."""
    path = fixtures.crossing(tmp_path / "crossing.xodr")
    subprocess.run([str(TOOL), "import", str(path), "--name", "c", "--out", str(tmp_path)],
                   check=True, capture_output=True)  # fmt: skip
    desc = yaml.safe_load((tmp_path / "c.yaml").read_text())
    light3 = next(t for t in desc["traffic_lights"] if t["id"] == 3)
    assert light3["crosses"] == [1, 2]
    light3["program"]["offset_s"] = 0.0
    bad = tmp_path / "bad.yaml"
    bad.write_text(yaml.safe_dump(desc))
    run = subprocess.run([str(TOOL), "check", str(bad)], capture_output=True, text=True)
    assert run.returncode != 0
    assert "light 3 crosses light 1 but the all-red interval" in run.stdout + run.stderr


def test_eye_cameras_see_every_lane(imported: dict[str, tuple[Path, dict, str]]) -> None:
    """The overhead cameras placed from the network's extent see every point of every driving
    lane's centre line at roof height, a whole roof tag's half diagonal (and 8 px) inside the
    image, as Tiny Town's do; a point off the network is not seen (the check can fail)."""
    for name, (path, doc, _) in imported.items():
        cams = eye_cameras.load(name, path.parent / "maps")
        assert 1 <= len(cams) <= 8, name
        for lane in doc["lanes"]:
            for p in lane["centre_line"]:
                assert any(c.sees(p["x_m"], p["y_m"], 0.1, 24) for c in cams), (name, p)
        far = doc["floor"]["half_size_m"] * 3
        assert not any(c.sees(far, far, 0.1, 24) for c in cams)


def _mark_lane(name: str) -> tuple[str, int, int]:
    """(road id, lane section, lane id) of a marking named mk_r<road>_s<section>_<c|l<n>|r<n>>_..."""
    m = re.fullmatch(r"mk_r(.+)_s(\d+)_(c|[lr]\d+)_\d+_\d+", name)
    assert m is not None, name
    key = m.group(3)
    return (
        m.group(1),
        int(m.group(2)),
        0 if key == "c" else int(key[1:]) * (1 if key[0] == "l" else -1),
    )


def test_road_marks_lie_on_pyxodr_borders(imported: dict[str, tuple[Path, dict, str]]) -> None:
    """Every stroke point of every marking lies on pyxodr's line of the lane border the file's
    roadMark is on (lane 0: the reference line with the lane offset), within 10 mm at full scale
    as the centre lines (measured 2026-12-03: 0.09 mm on the crossing, 2.2 mm on the widening
    lane of the sections road); every road mark of the file is drawn."""
    for name, (path, _, _) in imported.items():
        desc = yaml.safe_load((path.parent / "maps" / f"{name}.yaml").read_text())
        imp = desc["imported_from"]
        scale, (ox, oy) = imp["scale"], imp["offset_m"]
        borders = reference.border_lines(path)
        drawn = set()
        for mk in desc["markings"]:
            key = _mark_lane(mk["name"])
            drawn.add(key)
            for stroke in mk["strokes"]:
                for x, y in stroke:
                    q = np.array([(x - ox) / scale, (y - oy) / scale])
                    gap_mm = reference._seg_dist(q, borders[key]) * 1000
                    assert gap_mm <= 10.0, (name, mk["name"], gap_mm)
        root = ET.parse(path).getroot()
        marked = {(r.get("id"), i, int(ln.get("id", "0")))
                  for r in root.findall("road") for i, sec in enumerate(r.iter("laneSection"))
                  for ln in sec.iter("lane") if ln.find("roadMark") is not None}  # fmt: skip
        assert marked == drawn, name


def test_road_marks_solid_broken_and_yellow(imported: dict[str, tuple[Path, dict, str]]) -> None:
    """The crossing's centre lines: roads 1 and 4 broken (0.15 m lines, 3 m dashes, 9 m gaps,
    scaled), road 3 solid yellow, road 2 solid white, edges solid white 0.2 m. On road 4 (a
    straight) each dash is 3 m long and the next starts 12 m after it, within 1 mm at full scale."""
    path, _, _ = imported["crossing"]
    desc = yaml.safe_load((path.parent / "maps" / "crossing.yaml").read_text())
    s = 1 / 14
    by = {mk["name"]: mk for mk in desc["markings"]}
    for rid in ("1", "4"):
        mk = by[f"mk_r{rid}_s0_c_0_0"]
        assert (mk["kind"], mk["colour"]) == ("broken", "white")
        assert mk["width_m"] == pytest.approx(0.15 * s) and mk["dash_m"] == pytest.approx(
            [3 * s, 9 * s]
        )
        assert len(mk["strokes"]) >= 4, rid
    assert (by["mk_r3_s0_c_0_0"]["kind"], by["mk_r3_s0_c_0_0"]["colour"]) == ("solid", "yellow")
    assert (by["mk_r2_s0_c_0_0"]["kind"], by["mk_r2_s0_c_0_0"]["colour"]) == ("solid", "white")
    for rid in ("1", "2", "3", "4"):
        for side in ("l1", "r1"):
            edge = by[f"mk_r{rid}_s0_{side}_0_0"]
            assert (edge["kind"], len(edge["strokes"])) == ("solid", 1)
            assert edge["width_m"] == pytest.approx(0.2 * s)
    dashes = by["mk_r4_s0_c_0_0"]["strokes"]
    for a, b in zip(dashes, dashes[1:]):
        assert math.dist(a[0], a[-1]) / s == pytest.approx(3.0, abs=1e-3)
        assert math.dist(a[0], b[0]) / s == pytest.approx(12.0, abs=1e-3)


def test_route_lateral_is_measured_across_the_line() -> None:
    """The bench's lateral measure (city_drive._nearest): a car 0.4 m past a route's end (read
    late on a loaded machine) is measured across the line's last segment (10 mm), not by its
    distance from the end (400 mm); a car 0.2 m to the side in the middle is 0.2 m off."""
    poly = [(0.0, 0.0), (1.0, 0.0), (2.0, 0.0), (2.0, 0.0)]
    assert city_drive._nearest(poly, 2.4, 0.01) == pytest.approx((2.4, 0.01))
    assert city_drive._nearest(poly, 1.5, -0.2) == pytest.approx((1.5, 0.2))
    assert city_drive._nearest(poly, -0.3, 0.0) == pytest.approx((0.0, 0.3))  # before the start
