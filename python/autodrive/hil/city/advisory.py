"""A small V2I advisory publisher, the stand-in for the Smart City Manager's in tests and in the
smart-city mission until `autodrive-scm` runs: for each car, at 10 Hz (wall time), the next light
ahead of it on its lane (from the map's sidecar JSON and the car's EKF pose, <VEH>_POSE_MAP) with
the state the simulator publishes on TRAFFIC_LIGHT_STATE, the distance to its stop line, and the
next sign. "Ahead on its lane": the stop line lies ahead of the car along the lane's heading
(which matches the car's within 45 deg) and within the lane's half width plus a margin of its
centre line's straight approach; distances are straight-line along that heading.

CLI: python -m autodrive.hil.city.advisory --map tiny_town --vehicles NIGEL1,NIGEL2 [--lcm-url]
"""

from __future__ import annotations

import argparse
import json
import math
import select
import signal
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from types import FrameType
from typing import Any

from autodrive.core import channels, lcmtypes, v2x_auth, v2x_ca
from autodrive.core.v2x_cert import CertificateError
from autodrive.core.channels import channel
from autodrive.maps.loader import MAPS_DIR
from autodrive.core.settings import RELEASE_BUILD
from autodrive.core.geometry import wrap

PERIOD_S = 0.1  # 10 Hz per car
HEADING_TOL_RAD = math.radians(45.0)
LATERAL_TOL_M = 0.2  # half a lane width plus margin
BEHIND_TOL_M = 0.05  # a stop line this far behind the car's base_link still counts


@dataclass(frozen=True)
class Target:
    """A light's stop line or a sign: where it is and which way its lane runs."""

    ident: int
    kind: str  # "light" or the sign's kind
    x_m: float
    y_m: float
    heading_rad: float
    speed_limit_m_s: float


def _lane_heading_at(lane: dict[str, Any], x: float, y: float) -> float:
    pts = lane["centre_line"]
    best = min(pts, key=lambda p: (p["x_m"] - x) ** 2 + (p["y_m"] - y) ** 2)
    return float(best["heading_rad"])


def targets(map_json: Path) -> tuple[list[Target], list[Target]]:
    """(lights at their stop lines, signs) of a map's sidecar JSON."""
    d = json.loads(map_json.read_text())
    lanes = {lane["name"]: lane for lane in d["lanes"]}
    stops = {s["name"]: s for s in d["stop_lines"]}
    lights = []
    for t in d["traffic_lights"]:
        sl = stops[t["stop_line"]]
        x, y = sl["centre_m"]
        lights.append(Target(t["id"], "light", x, y, _lane_heading_at(lanes[t["lane"]], x, y), -1))
    signs = []
    for s in d["signs"]:
        x, y = s["position_m"]
        limit = s.get("speed_limit_m_s")
        heading = _lane_heading_at(lanes[s["lane"]], x, y)
        signs.append(Target(s["id"], s["kind"], x, y, heading, -1 if limit is None else limit))
    return lights, signs


def ahead(pose: tuple[float, float, float], t: Target) -> float | None:
    """Distance [m] along the lane from the car to t when t is ahead on the car's lane, else None."""
    x, y, yaw = pose
    if abs(wrap(yaw - t.heading_rad)) > HEADING_TOL_RAD:
        return None
    c, s = math.cos(t.heading_rad), math.sin(t.heading_rad)
    along = (t.x_m - x) * c + (t.y_m - y) * s
    lateral = -(t.x_m - x) * s + (t.y_m - y) * c
    if along < -BEHIND_TOL_M:
        return None
    # Signs stand beside the road: the lateral check is for stop lines only.
    if t.kind == "light" and abs(lateral) > LATERAL_TOL_M:
        return None
    return along


def nearest(pose: tuple[float, float, float], items: list[Target]) -> tuple[Target, float] | None:
    found = [(t, d) for t in items if (d := ahead(pose, t)) is not None]
    return min(found, key=lambda td: td[1]) if found else None


def run(map_name: str, vehicles: list[str], url: str, build: Path, stop: list[bool]) -> int:
    types = lcmtypes.load(build)
    lights, signs = targets(MAPS_DIR / f"{map_name}.json")
    lc = lcmtypes.bus(url)
    # Signed as the SCM it stands in for (SCM.cert), stamped with each car's own clock (its
    # latest pose's time: sim time in HIL), on which the car judges freshness.
    signer = v2x_auth.MessageSigner(v2x_ca.load_identity("SCM"))
    poses: dict[str, tuple[float, float, float]] = {}
    pose_utime: dict[str, int] = {}
    states: dict[int, tuple[int, float]] = {}

    def on_pose(ch: str, data: bytes) -> None:
        m = types.odometry_t.decode(data)
        poses[m.vehicle] = (m.x_m, m.y_m, m.yaw_rad)
        pose_utime[m.vehicle] = m.utime

    def on_light(_ch: str, data: bytes) -> None:
        m = types.traffic_light_state_t.decode(data)
        states[m.light_id] = (m.state, m.time_remaining_s)

    for v in vehicles:
        lc.subscribe(channel("POSE_MAP", v), on_pose)
    lc.subscribe(channel("TRAFFIC_LIGHT_STATE"), on_light)
    seq = 0
    next_t = time.monotonic()
    print(f"[advisory] {', '.join(vehicles)} on {map_name}: {len(lights)} lights", flush=True)
    while not stop[0]:
        wait = next_t - time.monotonic()
        if wait > 0:
            if select.select([lc.fileno()], [], [], wait)[0]:
                lc.handle()
            continue
        next_t += PERIOD_S
        for v in vehicles:
            if v not in poses:
                continue
            a = types.v2i_advisory_t()
            a.utime, a.seq, a.vehicle = int(time.time() * 1e6), seq, v
            a.light_id, a.light_state, a.light_time_remaining_s = -1, 0, -1.0
            a.stop_line_distance_m, a.sign_id, a.sign_kind = -1.0, -1, ""
            a.sign_distance_m, a.speed_limit_m_s = -1.0, -1.0
            light = nearest(poses[v], lights)
            if light is not None and light[0].ident in states:
                a.light_id = light[0].ident
                a.light_state, remaining = states[light[0].ident]
                a.light_time_remaining_s = remaining
                a.stop_line_distance_m = max(0.0, light[1])
            sign = nearest(poses[v], signs)
            if sign is not None:
                a.sign_id, a.sign_kind, a.sign_distance_m = sign[0].ident, sign[0].kind, sign[1]
            signer.sign(channel("V2I", v), a, pose_utime[v])
            lc.publish(channel("V2I", v), a.encode())
        seq += 1
    return 0


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(
        prog="python -m autodrive.hil.city.advisory", description=__doc__.split("\n\n")[0]
    )
    p.add_argument("--map", default="tiny_town", help="map name (maps/NAME.json)")
    p.add_argument("--vehicles", default=channels.vehicle_name(1), help="comma-separated cars")
    p.add_argument("--lcm-url", default=channels.load().url_default, help="LCM URL")
    p.add_argument("--build", default=str(RELEASE_BUILD), help="host build dir (LCM types)")
    args = p.parse_args(argv)
    if not (MAPS_DIR / f"{args.map}.json").is_file():
        p.error(f"--map {args.map}: no {MAPS_DIR / (args.map + '.json')}")
    stop = [False]

    def on_signal(_s: int, _f: FrameType | None) -> None:
        stop[0] = True

    signal.signal(signal.SIGINT, on_signal)
    signal.signal(signal.SIGTERM, on_signal)
    try:
        return run(args.map, args.vehicles.split(","), args.lcm_url, Path(args.build), stop)
    except CertificateError as err:
        print(f"[advisory] cannot sign as SCM: {err}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
