"""tools/map export: a kit map as OpenDRIVE 1.7, written with scenariogeneration. Every lane of
the map becomes a road whose reference line is the lane's centre line (its line and arc pieces,
offset and in driving order) with one right driving lane of the lane's width, centred on it by
a lane offset of half that width. A lane followed by exactly one lane, which follows only it,
is linked to it (road and lane links). Where lanes branch or merge, the lanes after a branch and
before a merge are connecting roads of a junction (one per group of them that touch): the roads
into it link to the junction and get a connection with a lane link to each connecting road
they lead into; a connecting road links to the roads before and after it. A marking painted on
a lane's border (an imported roadMark line) goes back as a <roadMark> of that lane's road: on its
centre lane (the lane's left border) or its driving lane (the right one), its lines in a <type>
(tOffset, dash, space, width); a marking of no lane (on a border between lanes that are not
driven) is not exported."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from scenariogeneration import xodr as sg  # type: ignore[import-untyped]

from autodrive.maps import geometry
from autodrive.maps.description import MapDescription
from autodrive.maps.model import Lane, MapDescriptionError, Marking, Piece, Vec2

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


def _successors(m: MapDescription) -> dict[str, list[str]]:
    """lane -> the lanes that start where it ends, tangent."""
    lanes = m.lanes()
    ends = {ln.name: _ends(m, ln) for ln in lanes}
    succ: dict[str, list[str]] = {ln.name: [] for ln in lanes}
    for a in lanes:
        end = ends[a.name][1]
        for b in lanes:
            start = ends[b.name][0]
            turn = abs(math.remainder(end[2] - start[2], 2 * math.pi))
            if a is not b and math.dist(end[:2], start[:2]) <= JOIN_M and turn <= JOIN_RAD:
                succ[a.name].append(b.name)
    return succ


def _junctions(succ: dict[str, list[str]]) -> dict[str, int]:
    """Connecting lane -> its junction (1..): the lanes after a branch or before a merge,
    grouped where they share a start or an end."""
    pred: dict[str, list[str]] = {n: [] for n in succ}
    for a, bs in succ.items():
        for b in bs:
            pred[b].append(a)
    inner = {b for a, bs in succ.items() for b in bs if len(bs) > 1 or len(pred[b]) > 1}
    group = {n: n for n in inner}

    def root(n: str) -> str:
        while group[n] != n:
            n = group[n]
        return n

    def join(a: str, b: str) -> None:
        group[root(a)] = root(b)

    for a, bs in succ.items():
        ins = [b for b in bs if b in inner]
        for b in ins[1:]:  # the same start
            join(ins[0], b)
    for b, As in pred.items():
        ins = [a for a in As if a in inner]
        for a in ins[1:]:  # the same end
            join(ins[0], a)
    ids: dict[str, int] = {}
    return {n: ids.setdefault(root(n), len(ids) + 1) for n in sorted(inner)}


def _along_m(p: Vec2, line: list[tuple[float, float, float]]) -> float:
    """Distance along a polyline to the point nearest p [m]."""
    best, along, total = math.inf, 0.0, 0.0
    for a, b in zip(line, line[1:]):
        dx, dy = b[0] - a[0], b[1] - a[1]
        seg = math.hypot(dx, dy)
        t = (
            0.0
            if seg == 0
            else max(0.0, min(1.0, ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / seg**2))
        )
        d = math.dist(p, (a[0] + t * dx, a[1] + t * dy))
        if d < best:
            best, along = d, total + t * seg
        total += seg
    return along


def _road_marks(m: MapDescription, lane: Lane, side: str) -> list[Any]:
    """The lane's markings on one side as roadMarks of its exported road, one per start along
    it (the lines of one imported roadMark start together), inside line (larger t) first."""
    line = m.centre_line(lane, 0.01)
    groups: dict[float, list[tuple[Marking, float]]] = {}
    for mk in m.markings:
        if mk.lane != lane.name or mk.side != side:
            continue
        starts = [_along_m(p, line) for st in mk.strokes for p in (st[0], st[-1])]
        groups.setdefault(round(min(starts), 4), []).append((mk, min(starts)))
    out = []
    for start in sorted(groups):
        lines = sorted(groups[start], key=lambda g: -g[0].offset_m)
        name = "_".join(mk.kind for mk, _ in lines) if len(lines) <= 2 else "custom"
        first = lines[0][0]
        colour = sg.RoadMarkColor.yellow if first.colour == "yellow" else sg.RoadMarkColor.white
        rm = sg.RoadMark(getattr(sg.RoadMarkType, name), first.width_m, soffset=start, color=colour)
        for mk, s0 in lines:
            dash, space = mk.dash_m if mk.dash_m is not None else (0.0, 0.0)
            rm.add_specific_road_line(sg.RoadLine(mk.width_m, dash, space, mk.offset_m, s0 - start))
        out.append(rm)
    return out


def build(m: MapDescription) -> Any:
    """The scenariogeneration OpenDrive of a kit map (road ids 1.., named after the lanes)."""
    lanes = m.lanes()
    if not lanes:
        raise MapDescriptionError(f"{m.source}: no lanes (roads or road tiles) to export")
    odr = sg.OpenDrive(m.name, revMajor="1", revMinor="7")
    ids = {ln.name: i + 1 for i, ln in enumerate(lanes)}
    succ = _successors(m)
    junction_of = _junctions(succ)
    jid = {j: len(ids) + j for j in set(junction_of.values())}  # ids after the roads'
    roads = {}
    for ln in lanes:
        pv = sg.PlanView()
        for x, y, h, length, k in _offset_pieces(ln):
            geom = sg.Line(length) if k == 0 else sg.Arc(k, length=length)
            pv.add_fixed_geometry(geom, x, y, h)
        centre = sg.Lane()
        for rm in _road_marks(m, ln, "left"):
            centre.add_roadmark(rm)
        section = sg.LaneSection(0, centre)
        driving = sg.Lane(a=2 * ln.half_width_m)
        for rm in _road_marks(m, ln, "right"):
            driving.add_roadmark(rm)
        section.add_right_lane(driving)
        lns = sg.Lanes()
        lns.add_lanesection(section)
        lns.add_laneoffset(sg.LaneOffset(0, ln.half_width_m, 0, 0, 0))
        j = jid[junction_of[ln.name]] if ln.name in junction_of else -1
        roads[ln.name] = sg.Road(ids[ln.name], pv, lns, road_type=j, name=ln.name)
    junctions = {j: sg.Junction(f"junction_{j}", j) for j in jid.values()}
    pred: dict[str, list[str]] = {n: [] for n in succ}
    for a, bs in succ.items():
        for b in bs:
            pred[b].append(a)
    for a, bs in succ.items():
        lane = roads[a].lanes.lanesections[0].rightlanes[0]
        if a not in junction_of and bs and bs[0] in junction_of:  # into a junction
            j = jid[junction_of[bs[0]]]
            roads[a].add_successor(sg.ElementType.junction, j)
            for b in bs:
                conn = sg.Connection(ids[a], ids[b], sg.ContactPoint.start)
                junctions[j].add_connection(conn.add_lanelink(-1, -1))
        elif len(bs) == 1:  # on to one road (a connecting road out of its junction, too)
            roads[a].add_successor(sg.ElementType.road, ids[bs[0]], sg.ContactPoint.start)
            lane.add_link("successor", -1)
        # a connecting road that branches again: no link (the importer joins it by geometry)
    for b, As in pred.items():
        lane = roads[b].lanes.lanesections[0].rightlanes[0]
        if b not in junction_of and As and As[0] in junction_of:  # out of a junction
            roads[b].add_predecessor(sg.ElementType.junction, jid[junction_of[As[0]]])
        elif len(As) == 1:
            roads[b].add_predecessor(sg.ElementType.road, ids[As[0]], sg.ContactPoint.end)
            lane.add_link("predecessor", -1)
    for r in roads.values():
        odr.add_road(r)
    for junction in junctions.values():
        odr.add_junction(junction)
    return odr


def write(m: MapDescription, out: Path) -> None:
    out.parent.mkdir(parents=True, exist_ok=True)
    build(m).write_xml(str(out))
