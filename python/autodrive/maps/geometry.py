"""Plane geometry of a description: road and lane centre lines, rectangle overlap, distances."""

from __future__ import annotations

import math

from autodrive.core.geometry import wrap

from autodrive.maps.model import Lane, Piece, Vec2


def piece_length_m(p: Piece, offset_m: float = 0.0) -> float:
    """Length of a piece, or of its parallel offset_m to the left."""
    if p.line is not None:
        return math.dist(p.line.from_m, p.line.to_m)
    assert p.arc is not None
    radius_m = p.arc.radius_m - offset_m * math.copysign(1.0, p.arc.sweep_deg)
    return abs(radius_m * math.radians(p.arc.sweep_deg))


def piece_point(p: Piece, s: float, offset_m: float = 0.0) -> tuple[Vec2, float]:
    """The point at fraction s (0..1) along a piece, moved offset_m to its left, and the heading
    [rad] of the piece there."""
    if p.line is not None:
        (x0, y0), (x1, y1) = p.line.from_m, p.line.to_m
        yaw = math.atan2(y1 - y0, x1 - x0)
        x, y = x0 + s * (x1 - x0), y0 + s * (y1 - y0)
    else:
        assert p.arc is not None
        a = math.radians(p.arc.start_deg + s * p.arc.sweep_deg)
        x = p.arc.centre_m[0] + p.arc.radius_m * math.cos(a)
        y = p.arc.centre_m[1] + p.arc.radius_m * math.sin(a)
        yaw = a + math.copysign(math.pi / 2, p.arc.sweep_deg)
    return (x - offset_m * math.sin(yaw), y + offset_m * math.cos(yaw)), yaw


def piece_ends(p: Piece) -> tuple[Vec2, Vec2]:
    return piece_point(p, 0.0)[0], piece_point(p, 1.0)[0]


def centre_line(lane: Lane, step_m: float = 0.05) -> list[tuple[float, float, float]]:
    """A lane's centre line as points (x, y, heading) [m, m, rad] in its driving direction, at
    most step_m apart, both ends included (a closed road's first point repeats at the end)."""
    if not step_m > 0:
        raise ValueError(f"centre_line: step_m must be > 0, got {step_m}")
    pts: list[tuple[float, float, float]] = []
    for p in lane.road.pieces:
        n = max(1, math.ceil(piece_length_m(p, lane.offset_m) / step_m - 1e-9))
        for k in range(0 if not pts else 1, n + 1):
            (x, y), yaw = piece_point(p, k / n, lane.offset_m)
            pts.append((x, y, yaw))
    if lane.direction == "backward":
        pts = [(x, y, wrap(yaw + math.pi)) for x, y, yaw in reversed(pts)]
    return pts


def seg_dist_m(p: Vec2, a: Vec2, b: Vec2) -> float:
    ax, ay = b[0] - a[0], b[1] - a[1]
    den = ax * ax + ay * ay
    t = 0.0 if den == 0 else max(0.0, min(1.0, ((p[0] - a[0]) * ax + (p[1] - a[1]) * ay) / den))
    return math.hypot(a[0] + t * ax - p[0], a[1] + t * ay - p[1])


def nearest_on_polyline(p: Vec2, pts: list[tuple[float, float, float]]) -> tuple[float, float]:
    """(distance [m], heading [rad] of the nearest segment) from p to a polyline."""
    best = (math.inf, 0.0)
    for a, b in zip(pts, pts[1:]):
        d = seg_dist_m(p, a[:2], b[:2])
        if d < best[0]:
            best = (d, math.atan2(b[1] - a[1], b[0] - a[0]))
    return best


def convex_overlap(pa: list[Vec2], pb: list[Vec2], eps: float = 1e-9) -> bool:
    """True when two convex polygons overlap with positive area (touching edges do not)."""
    for poly in (pa, pb):
        for i in range(len(poly)):
            (x0, y0), (x1, y1) = poly[i], poly[(i + 1) % len(poly)]
            nx, ny = y0 - y1, x1 - x0
            proj_a = [nx * x + ny * y for x, y in pa]
            proj_b = [nx * x + ny * y for x, y in pb]
            if max(proj_a) <= min(proj_b) + eps or max(proj_b) <= min(proj_a) + eps:
                return False
    return True
