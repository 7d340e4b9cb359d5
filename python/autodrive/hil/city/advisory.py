"""A small V2I advisory publisher, the stand-in for the Smart City Manager's in tests and in the
smart-city mission until `autodrive-scm` runs: for each car, at 10 Hz (wall time), the next light
ahead of it along its route with the state the simulator publishes on TRAFFIC_LIGHT_STATE, the
distance to its stop line, the next sign and the speed limit in force. "Ahead" is the SCM's own
rule, from the same code (autodrive.core.road_rules on the map's sidecar JSON): the car placed
on a lane from its EKF pose (<VEH>_POSE_MAP), its route's lanes first, then walked along its
route (--routes; without one it stops at a fork); distances are along the lanes.

CLI: python -m autodrive.hil.city.advisory --map tiny_town|PATH.json --vehicles NIGEL1,NIGEL2
     [--routes city_east,city_west] [--lcm-url URL]
"""

from __future__ import annotations

import argparse
import select
import signal
import sys
import time
from pathlib import Path
from types import FrameType
from typing import TYPE_CHECKING

from autodrive.core import channels, lcmtypes, v2x_auth, v2x_ca
from autodrive.core.v2x_cert import CertificateError
from autodrive.core.channels import channel
from autodrive.core.settings import RELEASE_BUILD
from autodrive.maps.loader import MAPS_DIR

if TYPE_CHECKING:  # imported in main, once the stop signals are handled (numpy, cffi: slow)
    from autodrive.core.road_rules import Ahead, Place, RoadNet

PERIOD_S = 0.1  # 10 Hz per car


class Advisor:
    """Each car's place and what lies ahead of it, from its poses (its last lane kept)."""

    def __init__(self, net: RoadNet, routes: dict[str, str]) -> None:
        self.net = net
        self.routes = routes
        self.places: dict[str, "Place | None"] = {}

    def ahead(self, vehicle: str, x_m: float, y_m: float, yaw_rad: float) -> "Ahead":
        route = self.routes.get(vehicle, "")
        place, ahead = self.net.follow(x_m, y_m, yaw_rad, route, self.places.get(vehicle))
        self.places[vehicle] = place
        return ahead


def run(
    map_name: str, net: RoadNet, vehicles: list[str], routes: dict[str, str], url: str,
    build: Path, stop: list[bool],
) -> int:  # fmt: skip
    types = lcmtypes.load(build)
    advisor = Advisor(net, routes)
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
    on = ", ".join(f"{v} ({routes.get(v) or 'no route'})" for v in vehicles)
    print(f"[advisory] {on} on {map_name}", flush=True)
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
            ahead = advisor.ahead(v, *poses[v])
            a = types.v2i_advisory_t()
            a.utime, a.seq, a.vehicle = int(time.time() * 1e6), seq, v
            a.light_id, a.light_state, a.light_time_remaining_s = -1, 0, -1.0
            a.stop_line_distance_m = -1.0
            if ahead.light_id in states:
                a.light_id = ahead.light_id
                a.light_state, a.light_time_remaining_s = states[ahead.light_id]
                a.stop_line_distance_m = ahead.stop_line_distance_m
            a.sign_id, a.sign_kind = ahead.sign_id, ahead.sign_kind
            a.sign_distance_m, a.speed_limit_m_s = ahead.sign_distance_m, ahead.speed_limit_m_s
            signer.sign(channel("V2I", v), a, pose_utime[v])
            lc.publish(channel("V2I", v), a.encode())
        seq += 1
    return 0


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(
        prog="python -m autodrive.hil.city.advisory", description=__doc__.split("\n\n")[0]
    )
    p.add_argument(
        "--map",
        default="tiny_town",
        help="map name (maps/NAME.json) or a sidecar's path (an imported map's NAME.json)",
    )
    p.add_argument("--vehicles", default=channels.vehicle_name(1), help="comma-separated cars")
    p.add_argument(
        "--routes",
        default="",
        help="each car's named route, comma-separated in the order of --vehicles (empty: none; "
        "the walk ahead then stops at a fork)",
    )
    p.add_argument("--lcm-url", default=channels.load().url_default, help="LCM URL")
    p.add_argument("--build", default=str(RELEASE_BUILD), help="host build dir (LCM types)")
    args = p.parse_args(argv)
    stop = [False]

    def on_signal(_s: int, _f: FrameType | None) -> None:
        stop[0] = True

    # before the slow part: a stop that comes while the network is built still ends us cleanly
    signal.signal(signal.SIGINT, on_signal)
    signal.signal(signal.SIGTERM, on_signal)
    from autodrive.core.road_rules import RoadNet, SidecarError

    sidecar = Path(args.map) if args.map.endswith(".json") else MAPS_DIR / f"{args.map}.json"
    if not sidecar.is_file():
        p.error(f"--map {args.map}: no {sidecar}")
    vehicles = args.vehicles.split(",")
    names = [r.strip() for r in args.routes.split(",")] if args.routes else []
    if names and len(names) != len(vehicles):
        p.error(f"--routes: {len(names)} routes for {len(vehicles)} vehicles")
    try:
        net = RoadNet.from_file(sidecar, Path(args.build))
    except SidecarError as err:
        p.error(f"--map {args.map}: {err}")
    for r in names:
        if r and r not in net.routes:
            p.error(f"--routes: no route '{r}' on {args.map} (has {', '.join(net.routes)})")
    routes = dict(zip(vehicles, names))
    try:
        return run(args.map, net, vehicles, routes, args.lcm_url, Path(args.build), stop)
    except CertificateError as err:
        print(f"[advisory] cannot sign as SCM: {err}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
