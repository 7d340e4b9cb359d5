"""Lanes of an OpenDRIVE road: the lateral position t [m] of a lane's borders and centre at s
(lane offset, then the width records of the lanes between it and the centre lane, or its own
border record), and which way traffic drives in it."""

from __future__ import annotations

import bisect
import math

from autodrive.maps.opendrive.reference_line import Point, ReferenceLine
from autodrive.maps.opendrive.xodr import Lane, LaneSection, Poly3, Road

DRIVING_TYPES = ("driving", "entry", "exit", "onRamp", "offRamp", "connectingRamp", "bidirectional")


def _record_at(records: list[Poly3], s_m: float) -> Poly3 | None:
    """The record in force at s_m: the last one starting at or before it."""
    if not records:
        return None
    i = max(0, bisect.bisect_right([r.s_m for r in records], s_m + 1e-12) - 1)
    return records[i]


class RoadLanes:
    """A road's lane geometry: points of lane centres and borders in the file's frame."""

    def __init__(self, road: Road) -> None:
        self.road = road
        self.ref = ReferenceLine(road)

    def section_range(self, i: int) -> tuple[float, float]:
        secs = self.road.sections
        end = secs[i + 1].s_m if i + 1 < len(secs) else self.road.length_m
        return secs[i].s_m, end

    def offset_m(self, s_m: float) -> float:
        rec = _record_at(self.road.lane_offsets, s_m)
        return rec.at(s_m) if rec is not None else 0.0

    def width_m(self, sec: LaneSection, lane: Lane, s_m: float) -> float:
        """The lane's width at s_m (from its width records, or from its and its inner
        neighbour's borders)."""
        return abs(self.outer_t(sec, lane.id, s_m) - self.inner_t(sec, lane.id, s_m))

    def outer_t(self, sec: LaneSection, lane_id: int, s_m: float) -> float:
        """t [m] of the lane's outer border (away from the centre lane) at s_m."""
        if lane_id == 0:
            return self.offset_m(s_m)
        lane = next((ln for ln in sec.lanes if ln.id == lane_id), None)
        side = 1.0 if lane_id > 0 else -1.0
        if lane is None:  # a gap in the ids: no width
            return self.outer_t(sec, lane_id - int(side), s_m)
        ds = s_m - sec.s_m
        if lane.borders:
            rec = _record_at(lane.borders, ds)
            assert rec is not None
            return self.offset_m(s_m) + side * rec.at(ds)
        rec = _record_at(lane.widths, ds)
        width = rec.at(ds) if rec is not None else 0.0
        return self.outer_t(sec, lane_id - int(side), s_m) + side * width

    def inner_t(self, sec: LaneSection, lane_id: int, s_m: float) -> float:
        return self.outer_t(sec, lane_id - (1 if lane_id > 0 else -1), s_m)

    def centre_t(self, sec: LaneSection, lane_id: int, s_m: float) -> float:
        return (self.outer_t(sec, lane_id, s_m) + self.inner_t(sec, lane_id, s_m)) / 2

    def point(self, s_m: float, t_m: float) -> Point:
        """The point t_m left of the reference line at s_m, and the reference line's heading."""
        x, y, h = self.ref.point_at(s_m)
        return x - t_m * math.sin(h), y + t_m * math.cos(h), h

    def forward(self, lane_id: int) -> bool:
        """True when traffic in the lane drives along +s (right lanes under RHT)."""
        return (lane_id < 0) == (self.road.rule == "RHT")
