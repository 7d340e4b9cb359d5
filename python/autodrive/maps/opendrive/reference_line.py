"""Points of an OpenDRIVE road's reference line: (x, y, heading) at a distance s along it, for
every planView geometry. Line and arc in closed form; spiral (clothoid), poly3 and paramPoly3
by Gauss-Legendre quadrature of the heading or of the curve's speed, which is exact to well
below a micrometre for road-sized pieces (checked against pyxodr in the tests)."""

from __future__ import annotations

import bisect
import math
from typing import Callable

import numpy as np
from numpy.typing import NDArray

from autodrive.maps.opendrive.xodr import Geometry, Road

Point = tuple[float, float, float]  # x [m], y [m], heading [rad]
_GL_X, _GL_W = np.polynomial.legendre.leggauss(12)  # type: ignore[no-untyped-call]
_GL_PIECE_M = 2.0  # quadrature on pieces of at most this length [m]


def _integrate(
    f: Callable[[NDArray[np.float64]], NDArray[np.float64]], a: float, b: float
) -> float:
    """The integral of f over [a, b] (12-point Gauss-Legendre on pieces <= 2 m)."""
    if b <= a:
        return 0.0
    n = max(1, math.ceil((b - a) / _GL_PIECE_M))
    edges = np.linspace(a, b, n + 1)
    total = 0.0
    for lo, hi in zip(edges, edges[1:]):
        mid, half = (lo + hi) / 2, (hi - lo) / 2
        total += float(np.dot(_GL_W, f(mid + half * _GL_X))) * half
    return total


def _local(g: Geometry, s: float) -> tuple[float, float, float]:
    """(u, v, heading) at s [m] from the geometry's start, in its start frame."""
    p = g.params
    if g.kind == "line":
        return s, 0.0, 0.0
    if g.kind == "arc":
        k = p["curvature"]
        if abs(k) < 1e-12:
            return s, 0.0, 0.0
        return math.sin(k * s) / k, (1 - math.cos(k * s)) / k, k * s
    if g.kind == "spiral":
        k0, rate = p["curvStart"], (p["curvEnd"] - p["curvStart"]) / g.length_m

        def theta(x: NDArray[np.float64]) -> NDArray[np.float64]:
            return k0 * x + 0.5 * rate * x * x

        u = _integrate(lambda x: np.cos(theta(x)), 0.0, s)
        v = _integrate(lambda x: np.sin(theta(x)), 0.0, s)
        return u, v, k0 * s + 0.5 * rate * s * s
    return _poly_local(g, s)


def _poly_coeffs(g: Geometry) -> tuple[tuple[float, ...], tuple[float, ...], float]:
    """u(p), v(p) coefficients (a, b, c, d) and the upper end of p."""
    p = g.params
    if g.kind == "poly3":  # v(u) with u itself as the parameter; its end found from the length
        return (0.0, 1.0, 0.0, 0.0), (p["a"], p["b"], p["c"], p["d"]), math.nan
    cu = (p["aU"], p["bU"], p["cU"], p["dU"])
    cv = (p["aV"], p["bV"], p["cV"], p["dV"])
    return cu, cv, 1.0 if g.p_range == "normalized" else g.length_m


def _speed(
    cu: tuple[float, ...], cv: tuple[float, ...]
) -> Callable[[NDArray[np.float64]], NDArray[np.float64]]:
    def f(x: NDArray[np.float64]) -> NDArray[np.float64]:
        du = cu[1] + x * (2 * cu[2] + 3 * x * cu[3])
        dv = cv[1] + x * (2 * cv[2] + 3 * x * cv[3])
        return np.hypot(du, dv)

    return f


def _poly_local(g: Geometry, s: float) -> tuple[float, float, float]:
    """A cubic's point at arc length s: the parameter p with arc length s found by Newton."""
    cu, cv, _ = _poly_coeffs(g)
    speed = _speed(cu, cv)
    x = s / max(1e-9, float(speed(np.array([0.0]))[0]))  # first guess
    for _ in range(30):
        err = _integrate(speed, 0.0, x) - s
        x -= err / max(1e-9, float(speed(np.array([x]))[0]))
        if abs(err) < 1e-10:
            break

    def ev(c: tuple[float, ...], t: float) -> float:
        return c[0] + t * (c[1] + t * (c[2] + t * c[3]))

    du = cu[1] + x * (2 * cu[2] + 3 * x * cu[3])
    dv = cv[1] + x * (2 * cv[2] + 3 * x * cv[3])
    return ev(cu, x), ev(cv, x), math.atan2(dv, du)


def geometry_point(g: Geometry, s: float) -> Point:
    """The point s [m] from the geometry's start (0 <= s <= its length), in the file's frame."""
    u, v, h = _local(g, s)
    c, sn = math.cos(g.hdg_rad), math.sin(g.hdg_rad)
    return float(g.x_m + c * u - sn * v), float(g.y_m + sn * u + c * v), float(g.hdg_rad + h)


def geometry_end(g: Geometry) -> Point:
    """The end of a geometry: for a cubic the end of its parameter range (where the next
    geometry should start), else the point at its length."""
    if g.kind in ("poly3", "paramPoly3"):
        return geometry_point(g, _poly_arc_length(g))
    return geometry_point(g, g.length_m)


def _poly_arc_length(g: Geometry) -> float:
    """A cubic's arc length over its parameter range (poly3: the record's length)."""
    cu, cv, p_end = _poly_coeffs(g)
    return g.length_m if math.isnan(p_end) else _integrate(_speed(cu, cv), 0.0, p_end)


class ReferenceLine:
    """A road's reference line: point_at(s) for 0 <= s <= the road's length. For cubics, s is
    spread over the curve's true arc length (pyxodr does the same for poly3; for paramPoly3 it
    spreads s over the parameter, which gives the same points but at other s)."""

    def __init__(self, road: Road) -> None:
        self.road = road
        self.starts = [g.s_m for g in road.geometries]

    def point_at(self, s: float) -> Point:
        i = max(0, bisect.bisect_right(self.starts, s) - 1)
        g = self.road.geometries[i]
        ds = min(max(0.0, s - g.s_m), g.length_m)
        if g.kind == "paramPoly3":  # spread the record's length over the curve's arc length
            ds *= _poly_arc_length(g) / g.length_m
        return geometry_point(g, ds)
