"""tools/export-mcap RUN.lcmlog [OUT.mcap]: an LCM log as MCAP with ROS 2 message schemas, so that
a run opens in Foxglove and in `ros2 bag` (no ROS installation needed).

Each channel of the log is looked up in the channel table (lcm_types/channels.yaml) and becomes
the topic /<vehicle>/<id> (/<id> for channels of no vehicle), in lower case:
- lidar_scan_t -> sensor_msgs/LaserScan, imu_t -> sensor_msgs/Imu, compressed_image_t ->
  sensor_msgs/CompressedImage, odometry_t -> nav_msgs/Odometry, pose2d_t and ground_truth_t ->
  geometry_msgs/PoseStamped, path2d_t -> nav_msgs/Path;
- every other type as JSON, with a JSON schema of its fields.
The TF tree goes on /tf and /tf_static: map -> <veh>/odom (from the map pose and the odometry),
<veh>/odom -> <veh>/base_link (odometry), and base_link to each sensor mount of
vehicle/nigel.params. With --map, the autonomy's saved map goes on /map as a
nav_msgs/OccupancyGrid. Times are the messages' own utime (sim time in a lockstep run)."""

from __future__ import annotations

import argparse
import json
import math
import sys
from collections import Counter
from pathlib import Path
from typing import Any, Callable, Optional

import numpy as np
import yaml
from mcap.well_known import MessageEncoding, SchemaEncoding
from mcap_ros2.writer import Writer as Ros2Writer

from autodrive.core import channels, lcmtypes, vehicle
from autodrive.core.settings import RELEASE_BUILD
from autodrive.core.runfiles import read_occupancy
from autodrive.devtools.inspect import frames, ros2_schemas
from autodrive.devtools.inspect.frames import MAP_FRAME, SENSOR_MOUNTS


Msg = dict[str, Any]


def _stamp(utime_us: int) -> Msg:
    sec, usec = divmod(int(utime_us), 1_000_000)
    return {"sec": sec, "nanosec": usec * 1000}


def _header(utime_us: int, frame: str) -> Msg:
    return {"stamp": _stamp(utime_us), "frame_id": frame}


def _quat_yaw(yaw_rad: float) -> Msg:
    return {"x": 0.0, "y": 0.0, "z": math.sin(yaw_rad / 2), "w": math.cos(yaw_rad / 2)}


def _pose2d(x_m: float, y_m: float, yaw_rad: float) -> Msg:
    return {"position": {"x": x_m, "y": y_m, "z": 0.0}, "orientation": _quat_yaw(yaw_rad)}


def _cov6(cov3: Any) -> list[float]:
    """A row-major 3x3 covariance of (x, y, yaw) in the 6x6 of (x, y, z, roll, pitch, yaw)."""
    out = [0.0] * 36
    idx = (0, 1, 5)
    for r in range(3):
        for c in range(3):
            out[idx[r] * 6 + idx[c]] = float(cov3[r * 3 + c])
    return out


def _transform(
    utime_us: int, parent: str, child: str, x: float, y: float, z: float, yaw: float
) -> Msg:
    return {
        "header": _header(utime_us, parent),
        "child_frame_id": child,
        "transform": {"translation": {"x": x, "y": y, "z": z}, "rotation": _quat_yaw(yaw)},
    }


def _json_schema(fields: Msg, title: str) -> Msg:
    def kind(v: Any) -> Msg:
        if isinstance(v, bool):
            return {"type": "boolean"}
        if isinstance(v, int):
            return {"type": "integer"}
        if isinstance(v, float):
            return {"type": "number"}
        if isinstance(v, str):
            return {"type": "string"}
        if isinstance(v, list):
            return {"type": "array", "items": kind(v[0]) if v else {}}
        if isinstance(v, dict):
            return {"type": "object", "properties": {k: kind(x) for k, x in v.items()}}
        return {}

    return {"title": title, "type": "object", "properties": {k: kind(v) for k, v in fields.items()}}


class McapOut(Ros2Writer):
    """The ROS 2 writer of mcap_ros2, plus JSON topics in the same file."""

    def __init__(self, path: Path) -> None:
        self._file = open(path, "wb")
        super().__init__(self._file)
        self._schemas: dict[str, Any] = {}
        self._json_channels: dict[str, int] = {}
        self.counts: Counter[str] = Counter()

    def ros2(self, topic: str, interface: str, msg: Msg, t_ns: int) -> None:
        if interface not in self._schemas:
            self._schemas[interface] = self.register_msgdef(
                ros2_schemas.ros2_type(interface), ros2_schemas.definition(interface)
            )
        self.write_message(topic, self._schemas[interface], msg, log_time=t_ns)
        self.counts[topic] += 1

    def json(self, topic: str, type_name: str, fields: Msg, t_ns: int) -> None:
        if topic not in self._json_channels:
            schema = json.dumps(_json_schema(fields, type_name)).encode()
            sid = self._writer.register_schema(type_name, SchemaEncoding.JSONSchema, schema)
            self._json_channels[topic] = self._writer.register_channel(
                topic=topic, message_encoding=MessageEncoding.JSON, schema_id=sid
            )
        data = json.dumps(fields, allow_nan=True).encode()
        self._writer.add_message(self._json_channels[topic], t_ns, data, t_ns)
        self.counts[topic] += 1

    def close(self) -> None:
        self.finish()  # type: ignore[no-untyped-call]
        self._file.close()


class Converter:
    """Turns the events of one LCM log into MCAP messages (one instance per log)."""

    def __init__(self, out: McapOut) -> None:
        self.out = out
        self.table = channels.load()
        self.car = vehicle.load()
        self.latest_odom: dict[str, tuple[float, float, float]] = {}  # vehicle -> x, y, yaw
        self.static_sent: set[str] = set()
        self.unknown: Counter[str] = Counter()
        self.handlers: dict[str, Callable[[str, str, Any, int], None]] = {
            "lidar_scan_t": self.lidar,
            "imu_t": self.imu,
            "compressed_image_t": self.image,
            "odometry_t": self.odometry,
            "pose2d_t": self.pose2d,
            "ground_truth_t": self.ground_truth,
            "path2d_t": self.path,
        }

    frame = staticmethod(frames.frame)

    def event(self, types: Any, channel: str, data: bytes, log_us: int) -> None:
        found = frames.resolve(self.table, channel)
        if found is None:
            self.unknown[channel] += 1
            return
        ch, veh = found
        msg = getattr(types, ch.type).decode(data)
        # a message without a stamp, or with a marker below 0 (EYE_FRAME_DONE's -1 "ready"), is
        # placed at its log time: MCAP's times are unsigned
        utime = int(getattr(msg, "utime", 0))
        utime = utime if utime > 0 else log_us
        topic = frames.topic(ch, veh)
        if veh and veh not in self.static_sent:
            self.static_tf(veh, utime)
        handler = self.handlers.get(ch.type)
        if handler:
            handler(topic, veh, msg, utime)
        else:
            self.out.json(topic, f"autodrive.{ch.type}", frames.lcm_fields(msg), utime * 1000)

    def static_tf(self, veh: str, utime: int) -> None:
        tfs = []
        for frame, key in SENSOR_MOUNTS.items():
            x, y, z = self.car.vector(key)
            tfs.append(
                _transform(
                    utime, self.frame(veh, "base_link"), self.frame(veh, frame), x, y, z, 0.0
                )
            )
        self.out.ros2("/tf_static", "tf2_msgs/TFMessage", {"transforms": tfs}, utime * 1000)
        self.static_sent.add(veh)

    def lidar(self, topic: str, veh: str, m: Any, utime: int) -> None:
        ros = {
            "header": _header(utime, self.frame(veh, m.frame_id or "laser")),
            "angle_min": m.angle_min_rad,
            "angle_max": m.angle_max_rad,
            "angle_increment": m.angle_increment_rad,
            "time_increment": m.time_increment_s,
            "scan_time": m.scan_time_s,
            "range_min": m.range_min_m,
            "range_max": m.range_max_m,
            "ranges": list(m.ranges_m),
            "intensities": list(m.intensities),
        }
        self.out.ros2(topic, "sensor_msgs/LaserScan", ros, utime * 1000)

    def imu(self, topic: str, veh: str, m: Any, utime: int) -> None:
        w, x, y, z = m.orientation_wxyz
        g, a = m.angular_velocity_rad_s, m.linear_acceleration_m_s2
        ros = {
            "header": _header(utime, self.frame(veh, m.frame_id or "imu_link")),
            "orientation": {"x": x, "y": y, "z": z, "w": w},
            "orientation_covariance": list(m.orientation_covariance),
            "angular_velocity": {"x": g[0], "y": g[1], "z": g[2]},
            "angular_velocity_covariance": list(m.angular_velocity_covariance),
            "linear_acceleration": {"x": a[0], "y": a[1], "z": a[2]},
            "linear_acceleration_covariance": list(m.linear_acceleration_covariance),
        }
        self.out.ros2(topic, "sensor_msgs/Imu", ros, utime * 1000)

    def image(self, topic: str, veh: str, m: Any, utime: int) -> None:
        ros = {
            "header": _header(utime, self.frame(veh, m.frame_id or "camera")),
            "format": m.format,
            "data": bytes(m.data),
        }
        self.out.ros2(topic + "/compressed", "sensor_msgs/CompressedImage", ros, utime * 1000)

    def odometry(self, topic: str, veh: str, m: Any, utime: int) -> None:
        parent, child = self.frame(veh, m.frame_id), self.frame(veh, m.child_frame_id)
        ros = {
            "header": _header(utime, parent),
            "child_frame_id": child,
            "pose": {
                "pose": _pose2d(m.x_m, m.y_m, m.yaw_rad),
                "covariance": _cov6(m.pose_covariance),
            },
            "twist": {
                "twist": {
                    "linear": {"x": m.vx_m_s, "y": m.vy_m_s, "z": 0.0},
                    "angular": {"x": 0.0, "y": 0.0, "z": m.yaw_rate_rad_s},
                },
                "covariance": _cov6(m.twist_covariance),
            },
        }
        self.out.ros2(topic, "nav_msgs/Odometry", ros, utime * 1000)
        # One parent per frame in a TF tree: odom -> base_link from the odometry, and
        # map -> odom from the map pose composed with the latest odometry.
        if m.frame_id == "odom":
            self.latest_odom[veh] = (m.x_m, m.y_m, m.yaw_rad)
            tf = _transform(utime, parent, child, m.x_m, m.y_m, 0.0, m.yaw_rad)
            self.out.ros2("/tf", "tf2_msgs/TFMessage", {"transforms": [tf]}, utime * 1000)
        elif m.frame_id == MAP_FRAME and veh in self.latest_odom:
            x, y, yaw = frames.map_to_odom((m.x_m, m.y_m, m.yaw_rad), self.latest_odom[veh])
            tf = _transform(utime, MAP_FRAME, self.frame(veh, "odom"), x, y, 0.0, yaw)
            self.out.ros2("/tf", "tf2_msgs/TFMessage", {"transforms": [tf]}, utime * 1000)

    def pose2d(self, topic: str, veh: str, m: Any, utime: int) -> None:
        ros = {
            "header": _header(utime, self.frame(veh, m.frame_id)),
            "pose": _pose2d(m.x_m, m.y_m, m.yaw_rad),
        }
        self.out.ros2(topic, "geometry_msgs/PoseStamped", ros, utime * 1000)

    def ground_truth(self, topic: str, veh: str, m: Any, utime: int) -> None:
        p, (w, x, y, z) = m.position_m, m.orientation_wxyz
        pose = {
            "position": {"x": p[0], "y": p[1], "z": p[2]},
            "orientation": {"x": x, "y": y, "z": z, "w": w},
        }
        ros = {"header": _header(utime, MAP_FRAME), "pose": pose}
        self.out.ros2(topic, "geometry_msgs/PoseStamped", ros, utime * 1000)

    def path(self, topic: str, veh: str, m: Any, utime: int) -> None:
        frame = self.frame(veh, m.frame_id)
        poses = [
            {"header": _header(utime, frame), "pose": _pose2d(x, y, yaw)}
            for x, y, yaw in zip(m.x_m, m.y_m, m.yaw_rad)
        ]
        self.out.ros2(
            topic, "nav_msgs/Path", {"header": _header(utime, frame), "poses": poses}, utime * 1000
        )

    def occupancy(self, map_yaml: Path, utime: int) -> None:
        grid = read_occupancy(map_yaml)
        with open(map_yaml) as f:
            meta = yaml.safe_load(f)
        occupied = float(meta.get("occupied_thresh", 0.65))
        free = float(meta.get("free_thresh", 0.196))
        p = (255.0 - grid.image.astype(np.float64)) / 255.0  # occupancy probability
        cells = np.full(p.shape, -1, dtype=np.int8)
        cells[p > occupied] = 100
        cells[p < free] = 0
        h, w = grid.image.shape
        info = {
            "map_load_time": _stamp(utime),
            "resolution": grid.resolution_m,
            "width": w,
            "height": h,
            "origin": _pose2d(grid.origin[0], grid.origin[1], 0.0),
        }
        data = cells[::-1].reshape(-1).tolist()  # ROS rows start at the origin (bottom)
        ros = {"header": _header(utime, MAP_FRAME), "info": info, "data": data}
        self.out.ros2("/map", "nav_msgs/OccupancyGrid", ros, utime * 1000)


def export_mcap(
    lcmlog: Path | str, mcap: Path | str, build: Path | str, map_yaml: Optional[Path | str] = None
) -> dict[str, int]:
    """Converts a log; returns the message count per topic. Raises ValueError on bad input."""
    lcmlog, mcap = Path(lcmlog), Path(mcap)
    if not lcmlog.is_file():
        raise ValueError(f"LCM log '{lcmlog}' does not exist")
    types = lcmtypes.load(build)
    out = McapOut(mcap)
    conv = Converter(out)
    last_utime = 0
    try:
        for ev in lcmtypes.events(lcmlog):
            try:
                conv.event(types, ev.channel, ev.data, int(ev.timestamp))
            except (ValueError, KeyError, IOError) as e:  # a malformed message: name it, go on
                conv.unknown[f"{ev.channel} (undecodable: {e})"] += 1
                continue
            last_utime = max(last_utime, int(ev.timestamp))
        if map_yaml is not None:
            conv.occupancy(Path(map_yaml), last_utime)
    finally:
        out.close()
    for channel, n in sorted(conv.unknown.items()):
        print(
            f"[export-mcap] skipped {n} message(s) on {channel}: not in the channel table",
            file=sys.stderr,
        )
    return dict(out.counts)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(
        prog="tools/export-mcap",
        description=__doc__.split("\n\n")[0] if __doc__ else None,
        epilog="example: tools/export-mcap out/demo/run.lcmlog   (writes out/demo/run.mcap; "
        "--map out/demo/map.yaml adds the saved map)",
    )
    p.add_argument("lcmlog", type=Path, help="the LCM log (lcm-logger output)")
    p.add_argument(
        "mcap",
        type=Path,
        nargs="?",
        help="the MCAP file to write (default: the log's path with .mcap instead of .lcmlog)",
    )
    p.add_argument("--map", type=Path, help="the autonomy's saved map (map.yaml) for /map")
    p.add_argument("--build", type=Path, default=RELEASE_BUILD, help="build dir with the LCM types")
    args = p.parse_args(argv)
    if args.mcap is None:
        args.mcap = args.lcmlog.with_suffix(".mcap")
    try:
        counts = export_mcap(args.lcmlog, args.mcap, args.build, args.map)
    except (ValueError, RuntimeError, OSError) as e:
        print(f"export-mcap: {e}", file=sys.stderr)
        return 1
    for topic, n in sorted(counts.items()):
        print(f"{topic}: {n}")
    print(f"wrote {args.mcap} ({sum(counts.values())} messages, {len(counts)} topics)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
