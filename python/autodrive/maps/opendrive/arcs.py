"""A smooth curve as the kit's road pieces: arcs through three of its points (a line where they
are in a row), split until each arc's end tangents and quarter points follow the curve."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

from autodrive.core.geometry import wrap

Vec2 = tuple[float, float]
MAX_TURN_ERR_RAD = 2e-4  # an arc's end tangent within this of the curve's (the kit: 1 mrad)
MAX_DEPTH = 12


@dataclass(frozen=True)
class Circle:
    """An arc from a to b: its centre, radius, start angle and signed sweep [m, m, rad, rad]."""

    centre: Vec2
    radius: float
    start_rad: float
    sweep_rad: float


def through(a: Vec2, m: Vec2, b: Vec2) -> Circle | None:
    """The arc from a through m to b; None when m is within 1e-9 of the chord's length off the
    chord (then a line)."""
    (ax, ay), (mx, my), (bx, by) = a, m, b
    chord = math.dist(a, b)
    cross = (mx - ax) * (by - ay) - (my - ay) * (bx - ax)  # < 0: m left of a->b
    if chord == 0 or abs(cross) / (chord * chord) < 1e-7:
        return None
    d = 2 * (ax * (my - by) + mx * (by - ay) + bx * (ay - my))
    ux = (
        (ax**2 + ay**2) * (my - by)
        + (mx**2 + my**2) * (by - ay)
        + (bx**2 + by**2) * (ay - my)
    ) / d
    uy = (
        (ax**2 + ay**2) * (bx - mx)
        + (mx**2 + my**2) * (ax - bx)
        + (bx**2 + by**2) * (mx - ax)
    ) / d
    start = math.atan2(ay - uy, ax - ux)
    sweep = (math.atan2(by - uy, bx - ux) - start) % (2 * math.pi)  # counter-clockwise
    if cross < 0:  # m left of a->b: clockwise
        sweep -= 2 * math.pi
    return Circle((ux, uy), math.hypot(ax - ux, ay - uy), start, sweep)


def _tangents(a: Vec2, b: Vec2, c: Circle | None) -> tuple[float, float]:
    if c is None:
        h = math.atan2(b[1] - a[1], b[0] - a[0])
        return h, h
    turn = math.copysign(math.pi / 2, c.sweep_rad)
    return c.start_rad + turn, c.start_rad + c.sweep_rad + turn


def _on(c: Circle | None, a: Vec2, b: Vec2, f: float) -> Vec2:
    if c is None:
        return a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1])
    t = c.start_rad + f * c.sweep_rad
    return c.centre[0] + c.radius * math.cos(t), c.centre[1] + c.radius * math.sin(t)


def _diff(x: float, y: float) -> float:
    return abs(wrap(x - y))


def split(
    point: Callable[[float], Vec2],
    heading: Callable[[float], float],
    s0: float,
    s1: float,
    max_len: float,
    max_dev: float,
) -> list[float]:
    """Parameters s0 = u0 < u1 < ... = s1, an odd count: each (u_2k, u_2k+1, u_2k+2) is one
    arc, at most max_len long in s, whose end tangents are within MAX_TURN_ERR_RAD of heading()
    and whose quarter points are within max_dev of the curve's."""
    n = max(1, math.ceil((s1 - s0) / max_len))
    out = [s0]
    for k in range(n):
        _refine(
            point, heading, s0 + (s1 - s0) * k / n, s0 + (s1 - s0) * (k + 1) / n, max_dev, out, 0
        )
    return out


def _refine(
    point: Callable[[float], Vec2],
    heading: Callable[[float], float],
    a: float,
    b: float,
    max_dev: float,
    out: list[float],
    depth: int,
) -> None:
    m = (a + b) / 2
    pa, pm, pb = point(a), point(m), point(b)
    c = through(pa, pm, pb)
    ta, tb = _tangents(pa, pb, c)
    ok = _diff(ta, heading(a)) < MAX_TURN_ERR_RAD and _diff(tb, heading(b)) < MAX_TURN_ERR_RAD
    for f in (0.25, 0.75):
        ok = ok and math.dist(_on(c, pa, pb, f), point(a + f * (b - a))) < max_dev
    if ok or depth >= MAX_DEPTH:
        out += [m, b]
        return
    _refine(point, heading, a, m, max_dev, out, depth + 1)
    _refine(point, heading, m, b, max_dev, out, depth + 1)
