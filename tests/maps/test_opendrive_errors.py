"""maps.opendrive_errors: each class of bad OpenDRIVE file (scenariogeneration's crossing with one
mistake, a bad roadMark among them) is refused by `tools/map import` with exit 2 and a message naming the file, the road
(or junction) id, the element and the field, and nothing is written."""

from __future__ import annotations

import subprocess
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Callable

import pytest

from autodrive.maps.model import MapDescriptionError
from autodrive.maps.opendrive import fixtures, importer
from pyhelpers import REPO_ROOT

TOOL = REPO_ROOT / "tools" / "map"


def _road(root: ET.Element, rid: str) -> ET.Element:
    return next(r for r in root.findall("road") if r.get("id") == rid)


def _geom(root: ET.Element, rid: str, i: int) -> ET.Element:
    return _road(root, rid).findall("planView/geometry")[i]


def _width(root: ET.Element, rid: str) -> ET.Element:
    w = _road(root, rid).find("lanes/laneSection/right/lane/width")
    assert w is not None
    return w


def _mark(root: ET.Element, rid: str) -> ET.Element:
    m = _road(root, rid).find("lanes/laneSection/right/lane/roadMark")
    assert m is not None
    return m


def _set(el: ET.Element, **kw: str) -> None:
    for k, v in kw.items():
        el.set(k, v)


def _gap(root: ET.Element) -> None:
    g = _geom(root, "1", 2)
    g.set("x", str(float(g.get("x", "0")) + 0.5))


def _unknown_geometry(root: ET.Element) -> None:
    g = _geom(root, "1", 0)
    for child in list(g):
        g.remove(child)
    ET.SubElement(g, "clothoidSpline")


def _missing_road(root: ET.Element) -> None:
    link = _road(root, "100").find("link/successor")
    assert link is not None
    link.set("elementId", "99")


def _missing_connecting_road(root: ET.Element) -> None:
    c = root.find("junction/connection")
    assert c is not None
    c.set("connectingRoad", "77")


def _no_driving_lanes(root: ET.Element) -> None:
    for lane in root.iter("lane"):
        if lane.get("type") == "driving":
            lane.set("type", "sidewalk")


CASES: dict[str, tuple[Callable[[ET.Element], None], str]] = {
    "nan": (lambda r: _set(_geom(r, "1", 1), x="nan"),
            "road '1': planView.geometry[1].x: not a finite number: 'nan'"),
    "unparsable": (lambda r: _set(_width(r, "2"), a="wide"),
                   "road '2': laneSection[0]: lane -1.width[0].a: not a number: 'wide'"),
    "negative_width": (lambda r: _set(_width(r, "3"), a="-3.5"),
                       "road '3': laneSection[0]: lane -1.width[0].a: negative width -3.5 m"),
    "gap": (_gap, "road '1': planView.geometry[2].x/y: starts 0.500 m from where geometry[1] ends"),
    "missing_road": (_missing_road, "road '100': link.successor.elementId: links to a missing road '99'"),
    "missing_connecting_road": (_missing_connecting_road,
                                "junction '100': connection[0].connectingRoad: links to a missing road '77'"),
    "version": (lambda r: _set(r.find("header"), revMajor="2", revMinor="0"),  # type: ignore[arg-type]
                "header.revMajor/revMinor: unsupported OpenDRIVE version 2.0 (supported: 1.4 to 1.8)"),
    "geometry": (_unknown_geometry, "road '1': planView.geometry[0]: unsupported geometry ['clothoidSpline']"),
    "no_lanes": (_no_driving_lanes, "lanes: no driving lane"),
    "mark_type": (lambda r: _set(_mark(r, "2"), type="zigzag"),
                  "road '2': laneSection[0]: lane -1.roadMark[0].type: unknown road mark type 'zigzag'"),
    "mark_width": (lambda r: _set(_mark(r, "3"), width="-0.2"),
                   "road '3': laneSection[0]: lane -1.roadMark[0].width: must be > 0, got -0.2 m"),
    "mark_colour": (lambda r: _set(_mark(r, "4"), color="pink"),
                    "road '4': laneSection[0]: lane -1.roadMark[0].color: unknown colour 'pink'"),
    "mark_dash": (lambda r: _set(_road(r, "1").find("lanes/laneSection/center/lane/roadMark/type/line"),  # type: ignore[arg-type]
                                 length="0"),
                  "road '1': laneSection[0]: lane 0.roadMark[0].type.line[0].length: a broken line (space > 0) needs a dash length > 0"),
}  # fmt: skip


@pytest.fixture(scope="module")
def crossing(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return fixtures.crossing(tmp_path_factory.mktemp("xodr") / "crossing.xodr")


@pytest.mark.parametrize("case", sorted(CASES))
def test_bad_file_is_refused_by_name(case: str, crossing: Path, tmp_path: Path) -> None:
    spoil, words = CASES[case]
    tree = ET.parse(crossing)
    spoil(tree.getroot())
    bad = tmp_path / f"bad_{case}.xodr"
    tree.write(bad)
    out = tmp_path / "out"
    if case == "nan":  # one case through the program: exit 2, one line, no traceback
        run = subprocess.run([str(TOOL), "import", str(bad), "--name", "bad", "--out", str(out)],
                             capture_output=True, text=True)  # fmt: skip
        assert run.returncode == 2 and f"{bad}: {words}" in run.stderr, run.stderr
        assert "Traceback" not in run.stderr
    with pytest.raises(MapDescriptionError) as err:  # the others in process (CPU: a loaded CI)
        importer.write(bad, 1 / 14, "bad", out)
    assert f"{bad}: {words}" in str(err.value)
    assert not out.exists()  # nothing half-written


def test_not_xml_and_missing_file(tmp_path: Path) -> None:
    bad = tmp_path / "garbage.xodr"
    bad.write_text("<OpenDRIVE><header")
    for path, words in ((bad, "not well-formed XML"), (tmp_path / "none.xodr", "cannot read")):
        run = subprocess.run([str(TOOL), "import", str(path), "--name", "x", "--out", str(tmp_path / "o")],
                             capture_output=True, text=True)  # fmt: skip
        assert run.returncode == 2 and f"{path}: {words}" in run.stderr, run.stderr


def test_bad_scale_is_refused() -> None:
    for scale in ("1:0", "-2", "big"):
        with pytest.raises(MapDescriptionError, match="--scale"):
            importer.parse_scale(scale)
