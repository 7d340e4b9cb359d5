"""tools/map export: a kit map as OpenDRIVE 1.7, written with scenariogeneration. Every lane of
the map becomes a road whose reference line is the lane's centre line (its line and arc pieces,
offset and in driving order) with one right driving lane of the lane's width, centred on it by
a lane offset of half that width. A lane followed by exactly one lane, which follows only it,
is linked to it (road and lane links); lanes that branch or merge are left for the importer to
join by geometry (it follows a lane into every lane that starts where it ends, tangent)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from scenariogeneration import xodr as sg  # type: ignore[import-untyped]

from autodrive.maps import geometry
from autodrive.maps.description import MapDescription
from autodrive.maps.model import Lane, MapDescriptionError, Piece

JOIN_M = 0.001  # lane ends within this, heading within JOIN_RAD, are successors [m]
JOIN_RAD = 0.001


def _offset_pieces(lane: Lane) -> list[tuple[float, float, float, float, float]]:
    """The lane's centre line in driving order as (x, y, heading, length, curvature) pieces."""
    out = []
    for p in lane.road.pieces:
        (x0, y0), h0 = geometry.piece_point(p, 0.0, lane.offset_m)
        (x1, y1), h1 = geometry.piece_point(p, 1.0, lane.offset_m)
        length = geometry.piece_length_m(p, lane.offset_m)
        k = _curvature(p, lane.offset_m)
        if lane.direction == "backward":
            out.append((x1, y1, h1 + math.pi, length, -k))
        else:
            out.append((x0, y0, h0, length, k))
    return out[::-1] if lane.direction == "backward" else out


def _curvature(p: Piece, offset_m: float) -> float:
    if p.arc is None:
        return 0.0
    sign = math.copysign(1.0, p.arc.sweep_deg)
    return sign / (p.arc.radius_m - offset_m * sign)


def _ends(m: MapDescription, lane: Lane) -> tuple[tuple[float, float, float], ...]:
    pts = m.centre_line(lane, 0.01)
    return pts[0], pts[-1]


def _links(m: MapDescription) -> dict[str, str]:
    """lane -> the one lane after it, where neither branches."""
    lanes = m.lanes()
    ends = {ln.name: _ends(m, ln) for ln in lanes}
    succ: dict[str, list[str]] = {ln.name: [] for ln in lanes}
    pred: dict[str, list[str]] = {ln.name: [] for ln in lanes}
    for a in lanes:
        end = ends[a.name][1]
        for b in lanes:
            start = ends[b.name][0]
            turn = abs(math.remainder(end[2] - start[2], 2 * math.pi))
            if a is not b and math.dist(end[:2], start[:2]) <= JOIN_M and turn <= JOIN_RAD:
                succ[a.name].append(b.name)
                pred[b.name].append(a.name)
    return {a: s[0] for a, s in succ.items() if len(s) == 1 and len(pred[s[0]]) == 1}


def build(m: MapDescription) -> Any:
    """The scenariogeneration OpenDrive of a kit map (road ids 1.., named after the lanes)."""
    lanes = m.lanes()
    if not lanes:
        raise MapDescriptionError(f"{m.source}: no lanes (roads or road tiles) to export")
    odr = sg.OpenDrive(m.name, revMajor="1", revMinor="7")
    ids = {ln.name: i + 1 for i, ln in enumerate(lanes)}
    roads = {}
    for ln in lanes:
        pv = sg.PlanView()
        for x, y, h, length, k in _offset_pieces(ln):
            geom = sg.Line(length) if k == 0 else sg.Arc(k, length=length)
            pv.add_fixed_geometry(geom, x, y, h)
        centre = sg.Lane()
        section = sg.LaneSection(0, centre)
        section.add_right_lane(sg.Lane(a=2 * ln.half_width_m))
        lns = sg.Lanes()
        lns.add_lanesection(section)
        lns.add_laneoffset(sg.LaneOffset(0, ln.half_width_m, 0, 0, 0))
        roads[ln.name] = sg.Road(ids[ln.name], pv, lns, name=ln.name)
    for a, b in _links(m).items():
        roads[a].add_successor(sg.ElementType.road, ids[b], sg.ContactPoint.start)
        roads[b].add_predecessor(sg.ElementType.road, ids[a], sg.ContactPoint.end)
        roads[a].lanes.lanesections[0].rightlanes[0].add_link("successor", -1)
        roads[b].lanes.lanesections[0].rightlanes[0].add_link("predecessor", -1)
    for r in roads.values():
        odr.add_road(r)
    return odr


def write(m: MapDescription, out: Path) -> None:
    out.parent.mkdir(parents=True, exist_ok=True)
    build(m).write_xml(str(out))
