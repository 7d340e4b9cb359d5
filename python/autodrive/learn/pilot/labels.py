"""Labels the picture determines: the steering pure pursuit would command from each frame's
ground-truth pose, on the lane centre line the expert drove, with a lookahead of our choosing.

Why: the front camera sees the ground only from ~0.41 m ahead of base_link, while the expert
drives with a 0.2 m lookahead. Its steering turns into a curve when the curve starts 0.2 m
ahead, a point below the picture: every frame from "curve 0.41 m ahead" to "0.2 m ahead"
looks alike but carries a label that changes, so the network learns the track's timing by
heart. With a lookahead at or past the camera's near edge, the label depends on the lane the
frame shows. The expert still drives (and perturbs) with its own 0.2 m lookahead; only the
label changes. Pure pursuit here is the simulator's (the one, common/path_tracking through cffi: the goal
`lookahead` along the path from the nearest point, delta = atan(2 wheelbase y / d^2)); the lane of
a recording with `lane_shift` is the route moved sideways as the simulator moves it
(`route_driver.c`)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import numpy.typing as npt

from autodrive import maps
from autodrive.core import pure_pursuit

F64 = npt.NDArray[np.float64]


def lane_polyline(map_name: str, route: str, lane_shift: int) -> tuple[F64, bool]:
    """The centre line [m] the expert drove (N x 2) and whether it is a loop."""
    r = maps.load(map_name).route(route)
    pts = np.asarray(r.polyline_m, dtype=float)
    if lane_shift:
        n = len(pts)
        prev = np.r_[n - 1 if r.loop else 0, np.arange(n - 1)]
        nxt = np.r_[np.arange(1, n), 0 if r.loop else n - 1]
        t = pts[nxt] - pts[prev]
        norm = np.hypot(t[:, 0], t[:, 1])
        for i in np.flatnonzero(norm < 1e-9):  # a closed loop's repeated end point
            k = i if i < n - 1 else i - 1
            t[i] = pts[k + 1] - pts[k]
            norm[i] = math.hypot(*t[i])
        d = lane_shift * 2.0 * r.half_width_m  # the map's lanes are adjacent
        pts = pts + d * np.stack([-t[:, 1], t[:, 0]], axis=1) / norm[:, None]
    return pts, r.loop


def pursuit_steering(poses: F64, line: F64, loop: bool, lookahead_m: float) -> F64:
    """Normalised steering of pure pursuit at lookahead_m for each pose (x, y, yaw) [m, rad]."""
    if lookahead_m <= 0:
        raise ValueError(f"label lookahead {lookahead_m} m: must be > 0")
    path = pure_pursuit.PathTracker([(float(x), float(y)) for x, y in line], loop)
    limit = pure_pursuit.default_vehicle().steer_limit_rad
    out = np.empty(len(poses))
    for k, (x, y, yaw) in enumerate(poses):
        out[k] = path.steer_nearest((float(x), float(y), float(yaw)), lookahead_m) / limit
    return out


def relabel(rows: list[dict[str, str]], manifest: dict[str, Any], lookahead_m: float) -> F64:
    """Pure pursuit labels at lookahead_m for a dataset's rows (`tools/pilot record`: pose
    columns, a `log` index into the manifest's source logs, whose meta name map, route and
    lane shift). ValueError names what is missing."""
    sources = manifest.get("source_logs", [])
    out = np.empty(len(rows))
    by_log: dict[int, list[int]] = {}
    for k, r in enumerate(rows):
        if r.get("x_m", "") == "":
            raise ValueError(f"frame {r.get('frame')}: no ground-truth pose to label from")
        by_log.setdefault(int(r["log"]), []).append(k)
    for li, idx in by_log.items():
        meta = sources[li].get("meta", {}) if li < len(sources) else {}
        if not meta.get("route"):
            raise ValueError(
                f"{sources[li].get('log') if li < len(sources) else f'log {li}'}: its meta names "
                "no route: cannot label by pure pursuit"
            )
        line, loop = lane_polyline(
            str(meta.get("map") or manifest["map"]), meta["route"], int(meta.get("lane_shift", 0))
        )
        poses = np.array([[float(rows[k][c]) for c in ("x_m", "y_m", "yaw_rad")] for k in idx])
        out[idx] = pursuit_steering(poses, line, loop, lookahead_m)
    return out
