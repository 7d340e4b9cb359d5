"""The driving lanes of an OpenDRIVE network as the kit's lanes, and how they join: each
(road, lane section, lane id) becomes a lane whose centre line runs in its traffic's direction,
sampled into short arcs; junction connections, lane links and road links become successor
links, and routes are walked through them."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field

from autodrive.core.geometry import wrap
from autodrive.maps.opendrive import arcs
from autodrive.maps.opendrive.lanes import DRIVING_TYPES, RoadLanes
from autodrive.maps.opendrive.xodr import Lane, Link, Network, OpenDriveError, Road

LaneKey = tuple[str, int, int]  # road id, lane section index, lane id
PIECE_M = 0.1  # the imported centre lines' arcs are about this long at model scale [m]
MAX_DEV_M = 5e-5  # the arcs' quarter points are this close to the curve (model scale) [m]
JOIN_M = 0.001  # a successor starts this close to where its lane ends (model scale) [m]
MAX_ROUTES = 400
MIN_WIDTH_M = 0.05  # a driving lane narrower than this somewhere (model scale) is not imported [m]


def safe_name(text: str) -> str:
    """A file id as a name for the kit (MJCF names): letters, digits and underscores."""
    return re.sub(r"[^A-Za-z0-9]", "_", text)


def lane_name(key: LaneKey) -> str:
    rid, sec, lid = key
    return f"r{safe_name(rid)}_s{sec}_{'l' if lid > 0 else 'r'}{abs(lid)}"


@dataclass
class ImportedLane:
    """A driving lane: its centre line points (x, y) [m, model scale, ours] in driving order
    at the s values along, and its smallest half width [m, model scale]."""

    key: LaneKey
    name: str
    s_m: list[float]  # the file's s of each point
    points: list[tuple[float, float]]
    half_width_m: float
    successors: list[LaneKey] = field(default_factory=list)


class Transform:
    """ours = scale * file + offset_m."""

    def __init__(self, scale: float, offset_m: tuple[float, float]) -> None:
        self.scale, self.offset_m = scale, offset_m

    def apply(self, x: float, y: float) -> tuple[float, float]:
        return self.scale * x + self.offset_m[0], self.scale * y + self.offset_m[1]


class LaneNetwork:
    def __init__(self, net: Network, scale: float) -> None:
        self.net = net
        self.scale = scale
        self.geo = {rid: RoadLanes(r) for rid, r in net.roads.items()}
        self.file_lanes: dict[LaneKey, tuple[list[float], list[tuple[float, float]], float]] = {}
        for rid, r in net.roads.items():
            for i, sec in enumerate(r.sections):
                for lane in sec.lanes:
                    if lane.type in DRIVING_TYPES:
                        self.file_lanes[(rid, i, lane.id)] = self._sample(r, i, lane)

    def lane_of(self, key: LaneKey) -> Lane | None:
        rid, i, lid = key
        r = self.net.roads.get(rid)
        if r is None or not 0 <= i < len(r.sections):
            return None
        return next((ln for ln in r.sections[i].lanes if ln.id == lid), None)

    def _sample(
        self, r: Road, i: int, lane: Lane
    ) -> tuple[list[float], list[tuple[float, float]], float]:
        """The lane's centre points in the file's frame, an odd count (each arc's start, middle
        and end, arcs following the curve: arcs.split), in driving order, and its smallest
        width [m]."""
        geo = self.geo[r.id]
        s0, s1 = geo.section_range(i)
        sec = r.sections[i]

        def point(s: float) -> tuple[float, float]:
            x, y, _ = geo.point(s, geo.centre_t(sec, lane.id, s))
            return x, y

        def heading(s: float) -> float:
            eps = min(1e-4, (s1 - s0) / 4)
            lo, hi = max(s0, s - eps), min(s1, s + eps)
            (x0, y0), (x1, y1) = point(lo), point(hi)
            return math.atan2(y1 - y0, x1 - x0)

        ss = arcs.split(point, heading, s0, s1, PIECE_M / self.scale, MAX_DEV_M / self.scale)
        pts = [point(s) for s in ss]
        width = min(geo.width_m(sec, lane, s) for s in ss)
        if not geo.forward(lane.id):
            ss, pts = ss[::-1], pts[::-1]
        return ss, pts, width

    # --- successors -----------------------------------------------------------------------

    def linked(self, key: LaneKey) -> list[LaneKey]:
        """The lanes the file links this lane to, in its driving direction."""
        rid, i, lid = key
        r = self.net.roads[rid]
        lane = self.lane_of(key)
        assert lane is not None
        fwd = self.geo[rid].forward(lid)
        nxt = lane.successor if fwd else lane.predecessor
        last = len(r.sections) - 1
        if (fwd and i < last) or (not fwd and i > 0):
            return [] if nxt is None else [(rid, i + 1 if fwd else i - 1, nxt)]
        link: Link | None = r.successor if fwd else r.predecessor
        if link is None:
            return []
        if link.element_type == "road":
            if nxt is None:
                return []
            other = self.net.roads[link.element_id]
            sec = 0 if link.contact_point != "end" else len(other.sections) - 1
            return [(other.id, sec, nxt)]
        out = []
        for c in self.net.junctions[link.element_id].connections:
            if c.incoming_road != rid:
                continue
            road = self.net.roads[c.connecting_road]
            sec = 0 if c.contact_point == "start" else len(road.sections) - 1
            out += [(road.id, sec, ll.to_lane) for ll in c.lane_links if ll.from_lane == lid]
        return out


def build(
    net: Network, scale: float, warnings: list[str]
) -> tuple[dict[LaneKey, ImportedLane], Transform]:
    """The driving lanes at model scale, centred on the origin, with their successors."""
    ln = LaneNetwork(net, scale)
    for key, (_, _, w) in list(ln.file_lanes.items()):
        if w * scale < MIN_WIDTH_M:  # the kit's lanes have one width
            warnings.append(
                f"lane {lane_name(key)}: opens or closes (narrowest {w:.2f} m); not a lane of the map"
            )
            del ln.file_lanes[key]
    if not ln.file_lanes:
        raise_no_lanes(net)
    xs = [p[0] for _, pts, _ in ln.file_lanes.values() for p in pts]
    ys = [p[1] for _, pts, _ in ln.file_lanes.values() for p in pts]
    centre = ((min(xs) + max(xs)) / 2, (min(ys) + max(ys)) / 2)
    tf = Transform(scale, (round(-scale * centre[0], 6), round(-scale * centre[1], 6)))
    lanes = {
        key: ImportedLane(key, lane_name(key), ss, [tf.apply(x, y) for x, y in pts], scale * w / 2)
        for key, (ss, pts, w) in ln.file_lanes.items()
    }
    for key, lane in lanes.items():
        end = lane.points[-1]

        def meets(k: LaneKey) -> bool:
            return (
                k in lanes
                and math.dist(lanes[k].points[0], end) <= JOIN_M
                and _tangent(lane, lanes[k])
            )

        linked = ln.linked(key)
        lane.successors = [k for k in linked if meets(k)]
        for k in linked:
            if k not in lane.successors:
                warnings.append(
                    f"lane {lane.name}: its link to {lane_name(k)} is not a driving "
                    f"lane that starts where it ends; not followed"
                )
        if not linked:  # no link in the file: a driving lane that starts where this one ends
            lane.successors = [k for k in lanes if k != key and meets(k)]
    return lanes, tf


def _end_heading(p: list[tuple[float, float]]) -> float:
    """The heading [rad] at p[-1] of the arc through p[-3], p[-2], p[-1] (an arc's start,
    middle and end): the last half chord's, turned on by half the turn between the chords."""
    h = [math.atan2(b[1] - a[1], b[0] - a[0]) for a, b in zip(p[-3:-1], p[-2:])]
    return h[-1] + (wrap(h[-1] - h[0]) / 2 if len(h) == 2 else 0.0)


def _tangent(a: ImportedLane, b: ImportedLane) -> bool:
    """b goes on in a's direction (the arcs' tangents where they meet within 0.02 rad)."""
    start = _end_heading([q for q in b.points[2::-1]]) + math.pi  # b's start, walked backwards
    return abs(wrap(_end_heading(a.points) - start)) < 0.02


def raise_no_lanes(net: Network) -> None:
    types = sorted({ln.type for r in net.roads.values() for s in r.sections for ln in s.lanes})
    raise OpenDriveError(
        f"{net.source}: lanes: no driving lane (at least {MIN_WIDTH_M} m wide at this scale) in "
        f"any road (lane types in the file: {types})"
    )


def routes(
    net: Network, lanes: dict[LaneKey, ImportedLane], max_junctions: int
) -> list[tuple[str, list[str]]]:
    """Every lane-to-lane path from the start of a road outside junctions, through up to
    max_junctions junctions, to the end of a road outside junctions (or a dead end): (name, lane
    names). Named by the roads and lanes it starts and ends in."""
    in_junction = {rid for rid, r in net.roads.items() if r.junction != "-1"}
    starts = [k for k in lanes if k[0] not in in_junction and _first_in_road(net, k)]
    out: list[list[LaneKey]] = []

    def walk(path: list[LaneKey], junctions: int) -> None:
        if len(out) >= MAX_ROUTES:
            return
        here = path[-1]
        go_on = []
        for k in lanes[here].successors:
            entering = k[0] in in_junction and here[0] not in in_junction
            if k not in path and not (entering and junctions >= max_junctions):
                go_on.append((k, junctions + (1 if entering else 0)))
        if not go_on:  # a dead end, a loop closed, or the last junction allowed passed
            if here[0] not in in_junction:
                out.append(path)
            return
        for k, j in go_on:
            walk(path + [k], j)

    for k in sorted(starts):
        walk([k], 0)
    named: list[tuple[str, list[str]]] = []
    seen: dict[str, int] = {}
    for path in out:
        a, b = path[0], path[-1]
        base = _tag(a) if _tag(a) == _tag(b) else f"{_tag(a)}_to_{_tag(b)}"
        seen[base] = seen.get(base, 0) + 1
        name = base if seen[base] == 1 else f"{base}_{seen[base]}"
        named.append((name, [lanes[k].name for k in path]))
    return named


def _tag(k: LaneKey) -> str:
    return f"r{safe_name(k[0])}{'l' if k[2] > 0 else 'r'}{abs(k[2])}"


def _first_in_road(net: Network, k: LaneKey) -> bool:
    rid, i, lid = k
    fwd = (lid < 0) == (net.roads[rid].rule == "RHT")
    return i == (0 if fwd else len(net.roads[rid].sections) - 1)


def _last_in_road(net: Network, k: LaneKey) -> bool:
    rid, i, lid = k
    fwd = (lid < 0) == (net.roads[rid].rule == "RHT")
    return i == (len(net.roads[rid].sections) - 1 if fwd else 0)
