"""maps.opendrive_import: `tools/map import` on OpenDRIVE networks that scenariogeneration writes
in the test (autodrive.maps.opendrive.fixtures): a 4-way junction of line, spiral, arc and both
kinds of paramPoly3 roads with lights, signs, an unknown signal and a slope; a road of three lane
sections with a lane offset, a poly3 geometry and a border record. The maps load and check, the
sidecar's centre lines lie within 10 mm (full scale) of pyxodr's, routes are walked through the
junction, signals become lights with stop lines and signs, the unknown one is listed, the slope
is flattened with a warning naming the road, and imported_from maps the file's points to ours."""

from __future__ import annotations

import json
import math
import subprocess
from pathlib import Path

import pytest

from autodrive.maps.opendrive import fixtures, reference
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
    assert len(doc["traffic_lights"]) == 2 and len(doc["stop_lines"]) == 2
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
