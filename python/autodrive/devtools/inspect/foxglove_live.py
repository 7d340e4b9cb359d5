"""tools/foxglove-live: a running car or simulation, live in Foxglove. Listens to the LCM bus and
serves Foxglove's WebSocket protocol (foxglove-sdk); open Foxglove, "Open connection",
ws://HOST:8765, and add a 3D panel.

What it carries, per channel of the channel table (topic /<vehicle>/<id>, lower case):
LIDAR scans (foxglove.LaserScan), odometry, map, Eye, AMCL and ground-truth poses
(foxglove.PoseInFrame), camera frames (foxglove.CompressedImage), planned paths
(foxglove.PosesInFrame), the TF tree on /tf (map -> <veh>/odom -> <veh>/base_link -> sensor
mounts of vehicle/nigel.params), the autonomy's saved map with --map (foxglove.Grid on /map),
and every other type, traffic lights among them, as JSON."""

from __future__ import annotations

import argparse
import json
import signal
import sys
import threading
import time
from pathlib import Path
from types import FrameType
from typing import Any, Callable, Optional

import foxglove
import foxglove.channels as fc
import foxglove.messages as fm
import numpy as np

from autodrive.core import channels, lcmtypes, vehicle
from autodrive.core.settings import instance
from autodrive.core.settings import RELEASE_BUILD
from autodrive.core.runfiles import read_occupancy
from autodrive.devtools.inspect import frames
from autodrive.devtools.inspect.frames import MAP_FRAME, SENSOR_MOUNTS

DEFAULT_PORT = 8765
STATIC_TF_PERIOD_S = 1.0  # a viewer that connects late still gets the mounts and the map


def _ts(utime_us: int) -> fm.Timestamp:
    sec, usec = divmod(int(utime_us), 1_000_000)
    return fm.Timestamp(sec, usec * 1000)


def _quat_yaw(yaw_rad: float) -> fm.Quaternion:
    return fm.Quaternion(x=0.0, y=0.0, z=float(np.sin(yaw_rad / 2)), w=float(np.cos(yaw_rad / 2)))


def _pose(x_m: float, y_m: float, yaw_rad: float) -> fm.Pose:
    return fm.Pose(position=fm.Vector3(x=x_m, y=y_m, z=0.0), orientation=_quat_yaw(yaw_rad))


class Bridge:
    """LCM messages in, Foxglove channels out (one channel per topic, made on first use)."""

    def __init__(self, types: Any, map_yaml: Optional[Path]) -> None:
        self.types = types
        self.table = channels.load()
        self.car = vehicle.load()
        self.map_yaml = map_yaml
        self.lock = threading.Lock()
        self.chans: dict[str, Any] = {}
        self.vehicles: set[str] = set()
        self.latest_odom: dict[str, frames.Pose2] = {}
        self.counts: dict[str, int] = {}
        self.handlers: dict[str, Callable[[str, str, Any, int], None]] = {
            "lidar_scan_t": self.lidar,
            "compressed_image_t": self.image,
            "odometry_t": self.odometry,
            "pose2d_t": self.pose2d,
            "ground_truth_t": self.ground_truth,
            "path2d_t": self.path,
        }

    def channel(self, topic: str, kind: Any) -> Any:
        if topic not in self.chans:
            self.chans[topic] = kind(topic)
        return self.chans[topic]

    def log(self, topic: str, kind: Any, msg: Any, utime: int) -> None:
        self.channel(topic, kind).log(msg, log_time=utime * 1000)
        self.counts[topic] = self.counts.get(topic, 0) + 1

    def tf(
        self, parent: str, child: str, x: float, y: float, z: float, yaw: float, utime: int
    ) -> None:
        t = fm.FrameTransform(
            timestamp=_ts(utime),
            parent_frame_id=parent,
            child_frame_id=child,
            translation=fm.Vector3(x=x, y=y, z=z),
            rotation=_quat_yaw(yaw),
        )
        self.log("/tf", fc.FrameTransformChannel, t, utime)

    def on_lcm(self, channel: str, data: bytes) -> None:
        found = frames.resolve(self.table, channel)
        if found is None:
            return  # LCM's own self-test and channels outside the table
        ch, veh = found
        try:
            msg = getattr(self.types, ch.type).decode(data)
        except (ValueError, KeyError) as e:
            print(
                f"[foxglove-live] {channel}: undecodable {ch.type} ({e}): skipped", file=sys.stderr
            )
            return
        utime = int(getattr(msg, "utime", 0)) or int(time.time() * 1e6)
        with self.lock:
            if veh:
                self.vehicles.add(veh)
            handler = self.handlers.get(ch.type)
            if handler:
                handler(frames.topic(ch, veh), veh, msg, utime)
            else:
                fields = json.dumps(frames.lcm_fields(msg), allow_nan=True)
                topic = frames.topic(ch, veh)
                if topic not in self.chans:
                    self.chans[topic] = foxglove.Channel(topic, message_encoding="json")
                self.chans[topic].log(fields.encode(), log_time=utime * 1000)
                self.counts[topic] = self.counts.get(topic, 0) + 1

    def lidar(self, topic: str, veh: str, m: Any, utime: int) -> None:
        scan = fm.LaserScan(
            timestamp=_ts(utime),
            frame_id=frames.frame(veh, m.frame_id or "laser"),
            start_angle=m.angle_min_rad,
            end_angle=m.angle_max_rad,
            ranges=[float(r) for r in m.ranges_m],
            intensities=[float(i) for i in m.intensities],
        )
        self.log(topic, fc.LaserScanChannel, scan, utime)

    def image(self, topic: str, veh: str, m: Any, utime: int) -> None:
        img = fm.CompressedImage(
            timestamp=_ts(utime),
            frame_id=frames.frame(veh, m.frame_id or "camera"),
            data=bytes(m.data),
            format=m.format,
        )
        self.log(topic, fc.CompressedImageChannel, img, utime)

    def odometry(self, topic: str, veh: str, m: Any, utime: int) -> None:
        self.pose2d(topic, veh, m, utime)  # the pose; the twist is not shown
        if m.frame_id == "odom":
            self.latest_odom[veh] = (m.x_m, m.y_m, m.yaw_rad)
            base = frames.frame(veh, m.child_frame_id)
            self.tf(frames.frame(veh, "odom"), base, m.x_m, m.y_m, 0.0, m.yaw_rad, utime)
        elif m.frame_id == MAP_FRAME and veh in self.latest_odom:
            x, y, yaw = frames.map_to_odom((m.x_m, m.y_m, m.yaw_rad), self.latest_odom[veh])
            self.tf(MAP_FRAME, frames.frame(veh, "odom"), x, y, 0.0, yaw, utime)

    def pose2d(self, topic: str, veh: str, m: Any, utime: int) -> None:
        pose = fm.PoseInFrame(
            timestamp=_ts(utime),
            frame_id=frames.frame(veh, m.frame_id),
            pose=_pose(m.x_m, m.y_m, m.yaw_rad),
        )
        self.log(topic, fc.PoseInFrameChannel, pose, utime)

    def ground_truth(self, topic: str, veh: str, m: Any, utime: int) -> None:
        p, (w, x, y, z) = m.position_m, m.orientation_wxyz
        pose = fm.Pose(
            position=fm.Vector3(x=p[0], y=p[1], z=p[2]),
            orientation=fm.Quaternion(x=x, y=y, z=z, w=w),
        )
        self.log(
            topic,
            fc.PoseInFrameChannel,
            fm.PoseInFrame(timestamp=_ts(utime), frame_id=MAP_FRAME, pose=pose),
            utime,
        )

    def path(self, topic: str, veh: str, m: Any, utime: int) -> None:
        poses = [_pose(x, y, yaw) for x, y, yaw in zip(m.x_m, m.y_m, m.yaw_rad)]
        msg = fm.PosesInFrame(
            timestamp=_ts(utime), frame_id=frames.frame(veh, m.frame_id), poses=poses
        )
        self.log(topic, fc.PosesInFrameChannel, msg, utime)

    def static(self) -> None:
        """The sensor mounts of every vehicle seen so far, and the saved map."""
        now = int(time.time() * 1e6)
        with self.lock:
            for veh in sorted(self.vehicles):
                for name, key in SENSOR_MOUNTS.items():
                    x, y, z = self.car.vector(key)
                    self.tf(
                        frames.frame(veh, "base_link"), frames.frame(veh, name), x, y, z, 0.0, now
                    )
            if self.map_yaml is not None:
                self.log("/map", fc.GridChannel, occupancy_grid(self.map_yaml, now), now)


def occupancy_grid(map_yaml: Path, utime: int) -> fm.Grid:
    """The autonomy's saved map (map_server YAML + PGM) as a Grid of occupancy 0..100."""
    grid = read_occupancy(map_yaml)
    occupancy = np.round((255.0 - grid.image[::-1].astype(np.float64)) / 255.0 * 100.0)
    h, w = grid.image.shape
    return fm.Grid(
        timestamp=_ts(utime),
        frame_id=MAP_FRAME,
        pose=_pose(grid.origin[0], grid.origin[1], 0.0),
        column_count=w,
        cell_size=fm.Vector2(x=grid.resolution_m, y=grid.resolution_m),
        row_stride=w,
        cell_stride=1,
        fields=[
            fm.PackedElementField(
                name="occupancy", offset=0, type=fm.PackedElementFieldNumericType.Uint8
            )
        ],
        data=occupancy.astype(np.uint8).tobytes(),
    )


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(
        prog="tools/foxglove-live",
        description=__doc__.split("\n\n")[0] if __doc__ else None,
        epilog="example: tools/foxglove-live --map out/demo/map.yaml   (then ws://localhost:8765)",
    )
    p.add_argument("--lcm-url", default=channels.load().url_default, help="LCM bus to listen to")
    p.add_argument("--host", default="127.0.0.1", help="address to serve on (0.0.0.0: the network)")
    p.add_argument(
        "--port", type=int, default=DEFAULT_PORT, help=f"WebSocket port ({DEFAULT_PORT})"
    )
    p.add_argument("--map", type=Path, help="the autonomy's saved map (map.yaml) for /map")
    p.add_argument("--build", type=Path, default=RELEASE_BUILD, help="build dir with the LCM types")
    p.add_argument("--duration", type=float, default=0.0, help="stop after S seconds (0: Ctrl-C)")
    args = p.parse_args(argv)
    if args.map is not None and not args.map.is_file():
        print(f"foxglove-live: --map '{args.map}' does not exist", file=sys.stderr)
        return 2
    try:
        bridge = Bridge(lcmtypes.load(args.build), args.map)
        bus = lcmtypes.bus(args.lcm_url)
    except (RuntimeError, OSError) as e:
        print(f"foxglove-live: {e}", file=sys.stderr)
        return 1
    bus.subscribe(".*", bridge.on_lcm)
    try:
        server = foxglove.start_server(name="autodrive", host=args.host, port=args.port)
    except Exception as e:  # the SDK raises its own error types for a taken or bad address
        print(
            f"foxglove-live: cannot serve on {args.host}:{args.port} ({e}): if the port is in use "
            f"(another foxglove-live, an SCM, another user's session), pick another with --port "
            f"P; {instance().describe()}",
            file=sys.stderr,
        )
        return 1
    print(f"foxglove-live: serving ws://{args.host}:{server.port} from {args.lcm_url}", flush=True)
    stop = threading.Event()

    def on_signal(_sig: int, _frame: FrameType | None) -> None:
        stop.set()

    signal.signal(signal.SIGINT, on_signal)
    signal.signal(signal.SIGTERM, on_signal)
    t_end = time.monotonic() + args.duration if args.duration > 0 else None
    next_static = 0.0
    while not stop.is_set() and (t_end is None or time.monotonic() < t_end):
        try:
            bus.handle_timeout(100)
        except OSError:  # interrupted by the stop signal
            if stop.is_set():
                break
            raise
        if time.monotonic() >= next_static:
            bridge.static()
            next_static = time.monotonic() + STATIC_TF_PERIOD_S
    server.stop()
    for topic, n in sorted(bridge.counts.items()):
        print(f"{topic}: {n}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
