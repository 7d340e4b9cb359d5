"""Road markings from an OpenDRIVE file's <roadMark>s as the kit's markings: each line of a mark
(a double mark has two) becomes a marking whose strokes (the whole line, or one per dash) are
polylines on the lane border the file puts it on (the lane's outer border; the centre lane's:
the reference line plus the lane offset), plus the line's tOffset, at model scale. Dashes are
laid out along s, as the file counts them. Types the kit does not paint (botts dots, grass,
curb, edge, a custom type without lines) and colours other than white and yellow are listed
in the warnings, never dropped silently."""

from __future__ import annotations

import math
from typing import Any, Callable

from autodrive.maps.opendrive.lanes import RoadLanes
from autodrive.maps.opendrive.network import ImportedLane, LaneKey, Transform, safe_name
from autodrive.maps.opendrive.xodr import MarkLine, Network, Road, RoadMark

MAX_DEV_M = 0.0005  # a stroke's chords stay this close to the border line (model scale) [m]
MAX_CHORD_M = 0.25  # and are at most this long (model scale) [m]
MIN_STROKE_M = 1e-4  # a dash clipped shorter than this (model scale) is not drawn [m]
COLOURS = {"standard": "white", "white": "white", "yellow": "yellow"}

Vec2 = tuple[float, float]


def _chords(
    f: Callable[[float], Vec2], a: float, b: float, tol: float, depth: int = 0
) -> list[float]:
    """s values from a to b whose chords of f stay within tol of f (midpoint test)."""
    pa, pb, m = f(a), f(b), (a + b) / 2
    (x0, y0), (x1, y1), (xm, ym) = pa, pb, f(m)
    chord = math.dist(pa, pb)
    off = (
        abs((x1 - x0) * (ym - y0) - (y1 - y0) * (xm - x0)) / chord
        if chord
        else math.dist(pa, (xm, ym))
    )
    if off <= tol or depth >= 16:
        return [a, b]
    return _chords(f, a, m, tol, depth + 1)[:-1] + _chords(f, m, b, tol, depth + 1)


def _stroke(f: Callable[[float], Vec2], a: float, b: float, scale: float) -> list[float]:
    """s values from a to b (file frame) for f (points at model scale, scale: model / file)."""
    n = max(1, math.ceil((b - a) * scale / MAX_CHORD_M))
    out = [a]
    for k in range(n):
        lo, hi = a + (b - a) * k / n, a + (b - a) * (k + 1) / n
        out += _chords(f, lo, hi, MAX_DEV_M)[1:]  # f is at model scale
    return out


def _dashes(line: MarkLine, start: float, end: float) -> list[tuple[float, float]]:
    """The s ranges painted by a line of a mark from start to end (file frame)."""
    first = start + line.s_offset_m
    if line.space_m == 0:
        return [(first, end)] if end > first else []
    out, s = [], first
    while s < end:
        out.append((s, min(s + line.length_m, end)))
        s += line.length_m + line.space_m
    return out


class _Owner:
    """Which kit lane a mark's border belongs to, and on which side of its traffic."""

    def __init__(self, road: Road, section: int, lane_id: int, lanes: dict[LaneKey, ImportedLane]):
        rht = road.rule == "RHT"
        outward = -1 if lane_id < 0 else 1
        # the border of lane_id (0: the centre line) is the outer border of lane_id and the
        # inner one of lane_id + outward (of +-1 for the centre line)
        tries = (
            [(-1, "inner"), (1, "inner")]
            if lane_id == 0
            else [(lane_id, "outer"), (lane_id + outward, "inner")]
        )
        self.lane: ImportedLane | None = None
        self.side: str | None = None
        self.forward = True
        for lid, where in tries:
            found = lanes.get((road.id, section, lid))
            if found is not None:
                self.lane = found
                self.side = "left" if (where == "inner") == rht else "right"
                self.forward = (lid < 0) == rht
                break


def _one_mark(road: Road, geo: RoadLanes, sec: int, lane_id: int, k: int, marks: list[RoadMark],
              tf: Transform, owner: _Owner, warnings: list[str]) -> list[dict[str, Any]]:  # fmt: skip
    mark = marks[k]
    s0, s1 = geo.section_range(sec)
    start = s0 + mark.s_m
    end = s0 + marks[k + 1].s_m if k + 1 < len(marks) else s1
    where = f"road '{road.id}': laneSection[{sec}]: lane {lane_id}.roadMark[{k}]"
    if mark.type == "none" or end <= start:
        return []
    if not mark.lines:
        warnings.append(f"{where}: type {mark.type!r} not drawn (the kit paints lines only)")
        return []
    colour = COLOURS.get(mark.colour)
    if colour is None:
        warnings.append(
            f"{where}: colour {mark.colour!r} drawn white (the kit has white and yellow)"
        )
        colour = "white"
    section = road.sections[sec]
    out = []
    for j, line in enumerate(mark.lines):

        def at(s: float, t_off: float = line.t_offset_m) -> Vec2:
            x, y, _ = geo.point(s, geo.outer_t(section, lane_id, s) + t_off)
            return tf.apply(x, y)

        strokes = [[at(s) for s in _stroke(at, a, b, tf.scale)]
                   for a, b in _dashes(line, start, end) if (b - a) * tf.scale >= MIN_STROKE_M]  # fmt: skip
        if not strokes:
            continue
        key = "c" if lane_id == 0 else f"{'l' if lane_id > 0 else 'r'}{abs(lane_id)}"
        spec: dict[str, Any] = {
            "name": f"mk_r{safe_name(road.id)}_s{sec}_{key}_{k}_{j}",
            "kind": "broken" if line.space_m > 0 else "solid",
            "colour": colour,
            "width_m": round(line.width_m * tf.scale, 9),
            "strokes": [[[round(x, 6), round(y, 6)] for x, y in st] for st in strokes],
        }
        if line.space_m > 0:
            spec["dash_m"] = [round(line.length_m * tf.scale, 9), round(line.space_m * tf.scale, 9)]
        if owner.lane is not None:
            spec["lane"], spec["side"] = owner.lane.name, owner.side
            spec["offset_m"] = round((1 if owner.forward else -1) * line.t_offset_m * tf.scale, 9)
        out.append(spec)
    return out


def markings(net: Network, lanes: dict[LaneKey, ImportedLane], tf: Transform,
             warnings: list[str]) -> list[dict[str, Any]]:  # fmt: skip
    """The kit description's markings (plain YAML types) of every road's road marks."""
    out: list[dict[str, Any]] = []
    for road in net.roads.values():
        geo = RoadLanes(road)
        for i, sec in enumerate(road.sections):
            owners = [(0, sec.centre_marks)] + [(ln.id, ln.marks) for ln in sec.lanes]
            for lane_id, marks in owners:
                owner = _Owner(road, i, lane_id, lanes)
                for k in range(len(marks)):
                    out += _one_mark(road, geo, i, lane_id, k, marks, tf, owner, warnings)
    return out
