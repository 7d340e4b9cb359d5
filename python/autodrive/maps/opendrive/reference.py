"""pyxodr as the reference for our sampler: its lane centre lines (traffic direction) of an
.xodr file, and the largest distance from an imported map's sidecar centre lines (taken back to
the file's frame with imported_from) to them, at full scale."""

from __future__ import annotations

import math
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from autodrive.maps.opendrive.lanes import DRIVING_TYPES
from autodrive.maps.opendrive.network import lane_name

RESOLUTION_M = 0.05  # pyxodr's sampling step (its lines are dense polylines) [m]


def lane_lines(path: Path) -> dict[tuple[str, int, int], NDArray[np.float64]]:
    """(road id, lane section index, lane id) -> pyxodr's centre line (x, y) [m] in driving
    order, for every driving lane."""
    from pyxodr.road_objects.network import RoadNetwork  # type: ignore[import-untyped]

    with tempfile.TemporaryDirectory() as tmp:
        net = RoadNetwork(str(_for_pyxodr(path, Path(tmp))), resolution=RESOLUTION_M)
        return _lines(net)


def border_lines(path: Path) -> dict[tuple[str, int, int], NDArray[np.float64]]:
    """(road id, lane section index, lane id) -> pyxodr's line (x, y) [m] of the lane's outer
    border, where a road mark of that lane is painted; every lane. Lane 0 (the reference line
    moved by the lane offset): the inner border of the lane next to it, 2 * its centre line - its
    outer border (pyxodr samples both at the same s; its section reference line has no offset)."""
    from pyxodr.road_objects.network import RoadNetwork

    out = {}
    with tempfile.TemporaryDirectory() as tmp:
        net = RoadNetwork(str(_for_pyxodr(path, Path(tmp))), resolution=RESOLUTION_M)
        for road in net.get_roads():
            for i, sec in enumerate(road.lane_sections):
                for lane in sorted(sec.lanes, key=lambda ln: -abs(int(ln.id))):  # +-1 last
                    outer = np.asarray(lane.boundary_line)[:, :2]
                    out[(str(road.id), i, int(lane.id))] = _extended(outer)
                    if abs(int(lane.id)) == 1:
                        inner = 2 * np.asarray(lane.centre_line)[:, :2] - outer
                        out[(str(road.id), i, 0)] = _extended(inner)
    return out


def _for_pyxodr(path: Path, folder: Path) -> Path:
    """A copy of the file with each spiral of constant curvature (scenariogeneration writes
    them in junctions) as the same arc: pyxodr 0.1.3 divides by the curvature's rate of change."""
    tree = ET.parse(path)
    for geom in tree.getroot().iter("geometry"):
        sp = geom.find("spiral")
        if sp is not None and float(sp.get("curvStart", "0")) == float(sp.get("curvEnd", "0")):
            geom.remove(sp)
            ET.SubElement(geom, "arc", {"curvature": sp.get("curvStart", "0")})
    out = folder / path.name
    tree.write(out)
    return out


def _lines(net: Any) -> dict[tuple[str, int, int], NDArray[np.float64]]:
    out = {}
    for road in net.get_roads():
        for i, sec in enumerate(road.lane_sections):
            for lane in sec.lanes:
                if lane.type in DRIVING_TYPES:
                    out[(str(road.id), i, int(lane.id))] = np.asarray(lane.traffic_flow_line)[:, :2]
    return out


def _seg_dist(p: NDArray[np.float64], line: NDArray[np.float64]) -> float:
    a, b = line[:-1], line[1:]
    ab = b - a
    den = np.maximum((ab * ab).sum(axis=1), 1e-18)
    t = np.clip(((p - a) * ab).sum(axis=1) / den, 0.0, 1.0)
    return float(np.min(np.hypot(*(a + t[:, None] * ab - p).T)))


def _extended(line: NDArray[np.float64]) -> NDArray[np.float64]:
    """The line going on straight for two steps at both ends: pyxodr ends a lane section's lines
    up to a step short of its end (the lateral error, curvature * (0.1 m)^2 / 2, is under 0.1 mm
    on these roads)."""

    def beyond(end: NDArray[np.float64], prev: NDArray[np.float64]) -> NDArray[np.float64]:
        d = end - prev
        return end + d / max(1e-9, float(np.hypot(d[0], d[1]))) * 2 * RESOLUTION_M

    return np.vstack([beyond(line[0], line[1]), line, beyond(line[-1], line[-2])])


def max_centre_deviation_m(path: Path, sidecar: dict[str, Any]) -> float:
    """The largest gap [m, full scale] between a sidecar centre-line point and pyxodr's centre
    line of the same lane (lanes named r<road>_s<section>_<l|r><n> by the importer)."""
    imp = sidecar["imported_from"]
    scale, (ox, oy) = imp["scale"], imp["offset_m"]
    by_name = {lane_name(key): _extended(line) for key, line in lane_lines(path).items()}
    worst = 0.0
    for lane in sidecar["lanes"]:
        if lane["name"] not in by_name:
            raise ValueError(f"{path}: lane {lane['name']}: pyxodr has no such lane")
        line = by_name[lane["name"]]
        for p in lane["centre_line"]:
            q = np.array([(p["x_m"] - ox) / scale, (p["y_m"] - oy) / scale])
            worst = max(worst, _seg_dist(q, line))
    return worst if math.isfinite(worst) else math.inf
