"""inspect.export_mcap: an LCM log with one message of each kind (written here with the generated
types) becomes an MCAP whose topics, counts and decoded fields are checked with the MCAP reader
and its ROS 2 decoder; a bad log is refused with a message that names it."""

from __future__ import annotations

import json
import math
import tempfile
from pathlib import Path

import lcm
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

from autodrive.core import channels
from autodrive.core import lcmtypes
from autodrive.devtools.inspect.export_mcap import export_mcap


def test_log_becomes_mcap(build_dir: Path) -> None:
    build = build_dir
    t = lcmtypes.load(build)
    VEH = "NIGEL1"

    def lidar(utime: int) -> object:
        m = t.lidar_scan_t()
        m.utime, m.frame_id = utime, "laser"
        m.angle_min_rad, m.angle_increment_rad = 0.0, 2 * math.pi / 360
        m.angle_max_rad = m.angle_increment_rad * 359
        m.range_min_m, m.range_max_m, m.scan_time_s = 0.15, 12.0, 1 / 7
        m.num_ranges = 360
        m.ranges_m = [1.0 + 0.01 * i for i in range(360)]
        m.intensities = [47.0] * 360
        return m

    def odom(utime: int, frame: str, x: float, yaw: float) -> object:
        m = t.odometry_t()
        m.utime, m.vehicle, m.frame_id, m.child_frame_id = utime, VEH, frame, "base_link"
        m.x_m, m.y_m, m.yaw_rad, m.vx_m_s = x, 0.5, yaw, 0.2
        return m

    def imu(utime: int) -> object:
        m = t.imu_t()
        m.utime, m.frame_id = utime, "imu_link"
        m.orientation_wxyz = [1.0, 0.0, 0.0, 0.0]
        m.linear_acceleration_m_s2 = [0.0, 0.0, 9.81]
        return m

    def image(utime: int) -> object:
        m = t.compressed_image_t()
        m.utime, m.frame_id, m.format, m.width_px, m.height_px = utime, "camera_front", "jpeg", 2, 2
        m.data = b"\xff\xd8fakejpeg"
        m.size_bytes = len(m.data)
        return m

    def pose(utime: int) -> object:
        m = t.pose2d_t()
        m.utime, m.vehicle, m.frame_id, m.x_m, m.y_m, m.yaw_rad = utime, VEH, "map", 1.5, -0.5, 0.3
        return m

    def path(utime: int) -> object:
        m = t.path2d_t()
        m.utime, m.vehicle, m.frame_id, m.plan, m.purpose = utime, VEH, "map", 1, "parking"
        m.num_poses = 3
        m.x_m, m.y_m, m.yaw_rad = [0.0, 0.1, 0.2], [0.0, 0.0, 0.05], [0.0, 0.0, 0.1]
        m.direction, m.curvature_1pm = [1, 1, 1], [0.0, 0.0, 0.5]
        return m

    def clock(utime: int) -> object:
        m = t.sim_clock_t()
        m.utime, m.real_time_factor = utime, 7.5
        return m

    messages = [
        ("LIDAR", lidar(1_000_000)),
        ("IMU", imu(1_010_000)),
        ("IMU", imu(1_020_000)),
        ("CAM_FRONT", image(1_030_000)),
        ("ODOM", odom(1_040_000, "odom", 0.25, 0.1)),
        ("POSE_MAP", odom(1_050_000, "map", 1.25, 0.4)),
        ("POSE_EYE", pose(1_060_000)),
        ("PATH", path(1_070_000)),
        ("SIM_CLOCK", clock(1_080_000)),
    ]
    with tempfile.TemporaryDirectory() as tmp:
        log_path, mcap_path = Path(tmp) / "run.lcmlog", Path(tmp) / "run.mcap"
        log = lcm.EventLog(str(log_path), "w", overwrite=True)
        for k, (cid, m) in enumerate(messages):
            ch = channels.load().by_id(cid)
            log.write_event(1_000_000 + k, ch.resolve(VEH if ch.per_vehicle else None), m.encode())
        log.write_event(2_000_000, "NOT_IN_THE_TABLE", b"\x00")
        log.close()

        counts = export_mcap(log_path, mcap_path, build)
        want = {
            "/nigel1/lidar": 1,
            "/nigel1/imu": 2,
            "/nigel1/cam_front/compressed": 1,
            "/nigel1/odom": 1,
            "/nigel1/pose_map": 1,
            "/nigel1/pose_eye": 1,
            "/nigel1/path": 1,
            "/sim_clock": 1,
            "/tf": 2,
            "/tf_static": 1,
        }
        assert counts == want, counts

        decoded: dict[str, list[object]] = {}
        encodings: dict[str, str] = {}
        with open(mcap_path, "rb") as f:
            reader = make_reader(f, decoder_factories=[DecoderFactory()])
            for schema, channel, message in reader.iter_messages():
                encodings[channel.topic] = channel.message_encoding
                if channel.message_encoding == "cdr":
                    dec = DecoderFactory().decoder_for("cdr", schema)
                    assert dec is not None, schema.name
                    decoded.setdefault(channel.topic, []).append(dec(message.data))
                else:
                    decoded.setdefault(channel.topic, []).append(json.loads(message.data))
        assert {k: len(v) for k, v in decoded.items()} == want, decoded.keys()

        scan = decoded["/nigel1/lidar"][0]
        assert scan.header.frame_id == "nigel1/laser" and len(scan.ranges) == 360  # type: ignore
        assert abs(scan.ranges[10] - 1.1) < 1e-6 and scan.header.stamp.sec == 1  # type: ignore
        assert decoded["/nigel1/imu"][1].linear_acceleration.z == 9.81  # type: ignore
        img = decoded["/nigel1/cam_front/compressed"][0]
        assert img.format == "jpeg" and bytes(img.data) == b"\xff\xd8fakejpeg"  # type: ignore
        od = decoded["/nigel1/odom"][0]
        assert od.child_frame_id == "nigel1/base_link" and od.pose.pose.position.x == 0.25  # type: ignore
        assert abs(od.pose.pose.orientation.z - math.sin(0.05)) < 1e-12  # type: ignore
        eye = decoded["/nigel1/pose_eye"][0]
        assert eye.header.frame_id == "map" and eye.pose.position.y == -0.5  # type: ignore
        assert len(decoded["/nigel1/path"][0].poses) == 3  # type: ignore
        assert encodings["/sim_clock"] == "json" and decoded["/sim_clock"][0]["real_time_factor"] == 7.5  # type: ignore
        # The TF tree: odom -> base_link, then map -> odom composed so that map -> base_link is
        # the map pose (x 1.25, yaw 0.4) given the odometry (x 0.25, yaw 0.1).
        tf_odom, tf_map = (m.transforms[0] for m in decoded["/tf"])  # type: ignore
        assert (tf_odom.header.frame_id, tf_odom.child_frame_id) == (
            "nigel1/odom",
            "nigel1/base_link",
        )
        assert (tf_map.header.frame_id, tf_map.child_frame_id) == ("map", "nigel1/odom")
        yaw_mo = 2 * math.atan2(tf_map.transform.rotation.z, tf_map.transform.rotation.w)
        c, s = math.cos(yaw_mo), math.sin(yaw_mo)
        x = tf_map.transform.translation.x + c * 0.25 - s * 0.5
        y = tf_map.transform.translation.y + s * 0.25 + c * 0.5
        assert abs(x - 1.25) < 1e-9 and abs(y - 0.5) < 1e-9 and abs(yaw_mo + 0.1 - 0.4) < 1e-9
        mounts = {tr.child_frame_id for tr in decoded["/tf_static"][0].transforms}  # type: ignore
        assert mounts == {
            "nigel1/laser",
            "nigel1/imu_link",
            "nigel1/camera_front",
            "nigel1/camera_rear",
        }

        # a missing log is named
        try:
            export_mcap(Path(tmp) / "missing.lcmlog", mcap_path, build)
            raise AssertionError("a missing log was accepted")
        except ValueError as e:
            assert "missing.lcmlog" in str(e), e
    print("export_mcap ok:", sum(want.values()), "messages on", len(want), "topics")
