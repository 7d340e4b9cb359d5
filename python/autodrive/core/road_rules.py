"""cffi binding (ABI mode) of autodrive_road_rules, the one "next light and sign ahead" that the
city driver uses too: lights and signs placed on a map's lanes by arc length, a car placed on a
lane, and the walk ahead along its route (the rules: common/road_rules/include/autodrive/
road_rules.h, whose CFFI markers give the declarations). Its input is a map's sidecar JSON
(maps/<map>.json, or autodrive.maps.sidecar.document of a map description)."""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import cffi
import numpy as np
import numpy.typing as npt

from autodrive.core.settings import settings
from autodrive.gym._lib import declarations, find_library

LIB_NAME = "libautodrive_road_rules.so"
HORIZON_M = 12.0  # how far ahead the walk looks [m] (ROAD_HORIZON_M)


def library_path(build: Path | None = None) -> Path:
    """The road rules library: in build/lib when a build is named (the one whose LCM types the
    caller uses), else see gym._lib.find_library."""
    if build is not None and (Path(build) / "lib" / LIB_NAME).is_file():
        return Path(build) / "lib" / LIB_NAME
    return find_library(LIB_NAME, "autodrive_road_rules_shared")


_loaded: list[tuple[Any, Any]] = []


def load(build: Path | None = None) -> tuple[Any, Any]:
    """(ffi, lib) of the library (the first load decides which library file serves)."""
    if not _loaded:
        ffi = cffi.FFI()
        ffi.cdef(declarations(settings().road_rules_header))
        _loaded.append((ffi, ffi.dlopen(str(library_path(build)))))
    return _loaded[0]


@dataclass(frozen=True)
class Place:
    """Where a car is: its lane, s_m along it, offset_m from its centre line [m]."""

    lane: str
    s_m: float
    offset_m: float


@dataclass(frozen=True)
class Ahead:
    """What lies ahead of a car (distances < 0 and ids -1 when none)."""

    light_id: int = -1
    stop_line_distance_m: float = -1.0
    sign_id: int = -1
    sign_kind: str = ""
    sign_distance_m: float = -1.0
    speed_limit_m_s: float = -1.0


@dataclass(frozen=True)
class Anchor:
    """A light's stop line or a sign on a lane, s_m along it."""

    kind: str  # "light" or "sign"
    id: int
    s_m: float
    sign_kind: str = ""
    speed_limit_m_s: float = -1.0


@dataclass
class Lane:
    name: str
    pts: npt.NDArray[np.float64]  # (n, 3): x, y, heading [m, m, rad]
    half_width_m: float
    length_m: float
    successors: list[str] = field(default_factory=list)


class SidecarError(ValueError):
    """A sidecar document the road network cannot be built from (names the element)."""


def _need(d: dict[str, Any], key: str, where: str) -> Any:
    if not isinstance(d, dict) or key not in d:
        raise SidecarError(f"{where}: missing key '{key}'")
    return d[key]


class RoadNet:
    """The road network of a map's sidecar document (dict, as maps/<map>.json holds it)."""

    def __init__(
        self, doc: dict[str, Any], source: str = "sidecar", build: Path | None = None
    ) -> None:
        ffi, lib = load(build)
        self.source = source
        lanes = _need(doc, "lanes", source)
        self._names = [str(_need(lane, "name", f"{source}: lanes[]")) for lane in lanes]
        index = {n: i for i, n in enumerate(self._names)}

        def lane_index(name: Any, where: str) -> int:
            if name not in index:
                raise SidecarError(f"{source}: {where}: lane '{name}' is not on the map")
            return index[name]

        keep: list[Any] = []  # the C arrays live while the library copies them
        c_lanes = ffi.new("road_lane_t[]", max(1, len(lanes)))
        self.lanes: dict[str, Lane] = {}
        for i, lane in enumerate(lanes):
            where = f"{source}: lane {self._names[i]}"
            pts = [
                (float(_need(p, "x_m", where)), float(_need(p, "y_m", where)),
                 float(_need(p, "heading_rad", where)))
                for p in _need(lane, "centre_line", where)
            ]  # fmt: skip
            c_pts = ffi.new(
                "road_point_t[]", [{"x_m": x, "y_m": y, "heading_rad": h} for x, y, h in pts]
            )
            keep.append(c_pts)
            half = float(_need(lane, "half_width_m", where))
            c_lanes[i] = {"points": c_pts, "n_points": len(pts), "half_width_m": half}
            self.lanes[self._names[i]] = Lane(self._names[i], np.array(pts, dtype=np.float64),
                                              half, 0.0)  # fmt: skip
        stops = {s["name"]: s for s in _need(doc, "stop_lines", source)}
        lights = _need(doc, "traffic_lights", source)
        c_lights = ffi.new("road_light_t[]", max(1, len(lights)))
        for i, t in enumerate(lights):
            where = f"traffic light {t.get('id')}"
            stop = stops.get(_need(t, "stop_line", f"{source}: {where}"))
            if stop is None:
                raise SidecarError(
                    f"{source}: {where}: stop line '{t['stop_line']}' is not on the map"
                )
            x, y = stop["centre_m"]
            c_lights[i] = {
                "id": int(t["id"]),
                "lane": lane_index(stop["lane"], where),
                "x_m": x,
                "y_m": y,
            }
        self._signs = _need(doc, "signs", source)
        c_signs = ffi.new("road_sign_t[]", max(1, len(self._signs)))
        for i, s in enumerate(self._signs):
            where = f"sign {s.get('id')}"
            x, y = _need(s, "position_m", f"{source}: {where}")
            lane = s.get("lane")
            limit = s.get("speed_limit_m_s")
            c_signs[i] = {
                "id": int(s["id"]),
                "lane": -1 if lane is None else lane_index(lane, where),
                "x_m": x,
                "y_m": y,
                "yaw_rad": float(_need(s, "yaw_rad", f"{source}: {where}")),
                "speed_limit_m_s": -1.0 if limit is None else float(limit),
            }
        routes = _need(doc, "routes", source)
        self.routes: dict[str, list[str]] = {}
        self._route_index: dict[str, int] = {}
        c_routes = ffi.new("road_route_t[]", max(1, len(routes)))
        for r, route in enumerate(routes):
            name = str(_need(route, "name", f"{source}: routes[]"))
            names = list(_need(route, "lanes", f"{source}: route {name}"))
            c_ids = ffi.new("int[]", [lane_index(n, f"route {name}") for n in names] or [0])
            keep.append(c_ids)
            c_routes[r] = {
                "lanes": c_ids,
                "n_lanes": len(names),
                "loop": int(bool(route.get("loop"))),
            }
            self.routes[name] = names
            self._route_index[name] = r
        err = ffi.new("char[]", 256)
        net = lib.road_net_create(c_lanes, len(lanes), c_lights, len(lights), c_signs,
                                  len(self._signs), c_routes, len(routes), err, 256)  # fmt: skip
        if net == ffi.NULL:
            raise SidecarError(f"{source}: {ffi.string(err).decode()}")
        self._net = ffi.gc(net, lib.road_net_destroy)
        for i, name in enumerate(self._names):
            g = self.lanes[name]
            g.length_m = float(lib.road_lane_length_m(self._net, i))
            out = ffi.new("int **")
            g.successors = [
                self._names[out[0][k]] for k in range(lib.road_lane_successors(self._net, i, out))
            ]

    @classmethod
    def from_file(cls, path: Path, build: Path | None = None) -> RoadNet:
        """The network of a sidecar JSON file (maps/<map>.json)."""
        try:
            doc = json.loads(Path(path).read_text())
        except (OSError, json.JSONDecodeError) as err:
            raise SidecarError(f"{path}: {err}") from err
        return cls(doc, str(path), build)

    def _route(self, route: str) -> int:
        return self._route_index.get(route, -1)

    def anchors(self, lane: str) -> list[Anchor]:
        """The lights and signs on a lane, in order of s."""
        ffi, lib = load()
        out = ffi.new("road_anchor_t **")
        n = lib.road_lane_anchors(self._net, self._names.index(lane), out)
        result = []
        for k in range(n):
            a = out[0][k]
            if a.kind == lib.ROAD_LIGHT:
                result.append(Anchor("light", int(a.id), float(a.s_m)))
            else:
                sign = self._signs[a.index]
                result.append(Anchor("sign", int(a.id), float(a.s_m), str(sign["kind"]),
                                     float(a.speed_limit_m_s)))  # fmt: skip
        return result

    def place(
        self, x_m: float, y_m: float, yaw_rad: float, route: str = "", last_lane: str = ""
    ) -> Place | None:
        """The lane the car is on (its route's first, then its last lane's), or None."""
        ffi, lib = load()
        out = ffi.new("road_place_t *")
        last = self._names.index(last_lane) if last_lane in self.lanes else -1
        if not lib.road_place_car(self._net, x_m, y_m, yaw_rad, self._route(route), last, out):
            return None
        return Place(self._names[out.lane], float(out.s_m), float(out.offset_m))

    def ahead(self, place: Place, route: str = "", horizon_m: float = HORIZON_M) -> Ahead:
        """The next light and sign within horizon_m [m] ahead along route (and the limit in force)."""
        ffi, lib = load()
        p = ffi.new("road_place_t *", {"lane": self._names.index(place.lane), "s_m": place.s_m,
                                       "offset_m": place.offset_m})  # fmt: skip
        a = lib.road_walk_ahead(self._net, p, self._route(route), horizon_m)
        limit = float(a.speed_limit_m_s)
        return Ahead(
            light_id=int(a.light_id),
            stop_line_distance_m=float(a.stop_line_distance_m),
            sign_id=int(a.sign_id),
            sign_kind=str(self._signs[a.sign_index]["kind"]) if a.sign_index >= 0 else "",
            sign_distance_m=float(a.sign_distance_m),
            speed_limit_m_s=limit if limit > 0 else -1.0,
        )

    def follow(
        self, x_m: float, y_m: float, yaw_rad: float, route: str, last: Place | None
    ) -> tuple[Place | None, Ahead]:
        """A car's place from its pose (its last place breaking ties) and what lies ahead of it
        along its route: the one per-pose step of every advisor."""
        place = self.place(x_m, y_m, yaw_rad, route, last.lane if last else "")
        return place, self.ahead(place, route) if place else Ahead()

    def next_lane(self, lane: str, route: str = "") -> str | None:
        """The lane after lane along route, else its one successor, else None."""
        _, lib = load()
        k = lib.road_next_lane(self._net, self._names.index(lane), self._route(route))
        return None if k < 0 else self._names[k]
