"""autodrive-ros-bridge: one rospy node for one or more cars. It republishes the cars' LCM
channels as standard ROS messages (the table: autodrive.ros.topics, derived from
lcm_types/channels.yaml), the tf tree map -> odom -> base_link -> laser / imu_link / cameras
(static offsets from vehicle/nigel.params) and SIM_CLOCK as /clock, and it takes commands on
/<car>/cmd_vel (Twist, through the car's model) and /<car>/throttle, /<car>/steering (Float32).

Commands go the guarded way every command source goes (docs/design/safety.md): each is signed
with the car's key as source `ros` (autodrive.core.command_auth, the same signer as the other
Python sources), sent at 50 Hz while ROS commands keep coming, which renews the control lease;
once no ROS command came for --quiet-s (on the sim clock when it runs, else on the wall clock)
the bridge sends disengaged stops and then nothing, so the lease lapses. Stamps are the LCM
messages' own (sim time in HIL: set /use_sim_time for ROS tools)."""

from __future__ import annotations

import argparse
import importlib
import math
import select
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from autodrive.core import channels, command_auth, lcmtypes, vehicle
from autodrive.core.settings import settings
from autodrive.ros import topics

SOURCE = "ros"
COMMAND_PERIOD_S = 0.02  # 50 Hz, the rate of <VEH>_COMMAND in the channel table
QUIET_S_DEFAULT = 0.5  # no ROS command for this long: stop
STOP_COMMANDS = 5  # disengaged zero commands sent when the ROS side goes quiet
STATIC_TF_PERIOD_S = 1.0


RECV_BUF_BYTES = 4 * 1024 * 1024  # the UDP receive buffer asked for (capped by net.core.rmem_max)


def with_receive_buffer(url: str) -> str:
    """The LCM URL with a large UDP receive buffer (LCM's recv_buf_size), so that a process
    that falls behind for a moment on a loaded machine loses no message."""
    if not url.startswith("udpm://") or "recv_buf_size=" in url:
        return url
    return url + ("&" if "?" in url else "?") + f"recv_buf_size={RECV_BUF_BYTES}"


class BridgeError(RuntimeError):
    """Something the bridge cannot start without; the message names it."""


# rospy, the master's client library and the message packages the bridge uses (Debian's
# python3-rospy, python3-<package>); a message package by its name, its module is <name>.msg.
ROS_LIBRARIES = ("rospy", "rosgraph")
ROS_MESSAGE_PACKAGES = ("geometry_msgs", "nav_msgs", "sensor_msgs", "std_msgs", "tf2_msgs",
                        "rosgraph_msgs")  # fmt: skip


def ros_modules() -> dict[str, Any]:
    """Name -> module of ROS_LIBRARIES and ROS_MESSAGE_PACKAGES, or BridgeError naming the
    missing one."""
    names = [(n, n) for n in ROS_LIBRARIES] + [(n, n + ".msg") for n in ROS_MESSAGE_PACKAGES]
    try:
        return {name: importlib.import_module(module) for name, module in names}
    except ImportError as e:
        raise BridgeError(
            f"ROS 1 Python modules missing ({e.name}): install Debian's python3-rospy and the "
            "message packages (tools/setup does)"
        ) from None


def quaternion_of_yaw(yaw_rad: float) -> tuple[float, float, float, float]:
    """(x, y, z, w) of a rotation about z."""
    return (0.0, 0.0, math.sin(yaw_rad / 2), math.cos(yaw_rad / 2))


def twist_to_command(
    v_m_s: float,
    yaw_rate_rad_s: float,
    top_speed_m_s: float,
    wheelbase_m: float,
    steer_limit_rad: float,
) -> tuple[float, float]:
    """(throttle, steering), normalised [-1, 1], of a Twist through the kinematic bicycle:
    throttle = v / top speed, steering angle = atan(wheelbase * yaw rate / v). An Ackermann car
    cannot turn on the spot: at |v| < 1 mm/s the steering is 0."""
    throttle = max(-1.0, min(1.0, v_m_s / top_speed_m_s))
    if abs(v_m_s) < 1e-3:
        return throttle, 0.0
    angle = math.atan(wheelbase_m * yaw_rate_rad_s / v_m_s)
    return throttle, max(-1.0, min(1.0, angle / steer_limit_rad))


@dataclass
class CarModel:
    top_speed_m_s: float
    wheelbase_m: float
    steer_limit_rad: float
    offsets_m: dict[str, tuple[float, ...]]  # child frame -> (x, y, z) from base_link


def car_model() -> CarModel:
    v = vehicle.load()
    offsets = {
        "laser": v.vector("lidar_pos_m"),
        "imu_link": v.vector("imu_pos_m"),
        "camera_front": v.vector("cam_front_pos_m"),
        "camera_rear": v.vector("cam_rear_pos_m"),
    }
    top = v.number("motor_noload_speed_rad_s") * v.number("wheel_radius_m")
    return CarModel(top, v.number("wheelbase_m"), v.number("steer_limit_rad"), offsets)


class Commander:
    """One car's ROS command path: the newest ROS input, signed and sent at 50 Hz while fresh."""

    def __init__(self, m: dict[str, Any], types: Any, lc: Any, car: str, model: CarModel,
                 signer: command_auth.Signer, quiet_s: float, now_s: Callable[[], float]) -> None:  # fmt: skip
        self.types, self.lc, self.model, self.signer = types, lc, model, signer
        self.channel = channels.channel(topics.COMMAND_ID, car)
        self.quiet_s, self.now_s = quiet_s, now_s
        self.throttle = self.steering = 0.0
        self.last_input_s: float | None = None
        self.armed = False  # the disengaged command of the Nano's arming edge went out
        self.stops_left = 0
        self.seq = 0
        self.sent = 0
        self.lock = threading.Lock()  # ROS callbacks and the 50 Hz tick run on other threads
        rospy = m["rospy"]
        rospy.Subscriber(
            topics.command_topic(car, "cmd_vel"),
            m["geometry_msgs"].Twist,
            self.on_twist,
            tcp_nodelay=True,
        )
        rospy.Subscriber(
            topics.command_topic(car, "throttle"),
            m["std_msgs"].Float32,
            self.on_throttle,
            tcp_nodelay=True,
        )
        rospy.Subscriber(topics.command_topic(car, "steering"), m["std_msgs"].Float32, self.on_steering, tcp_nodelay=True)  # fmt: skip

    def on_twist(self, msg: Any) -> None:
        mm = self.model
        with self.lock:
            self.throttle, self.steering = twist_to_command(
                msg.linear.x, msg.angular.z, mm.top_speed_m_s, mm.wheelbase_m, mm.steer_limit_rad
            )
            self.fresh()

    def on_throttle(self, msg: Any) -> None:
        with self.lock:
            self.throttle = max(-1.0, min(1.0, float(msg.data)))
            self.fresh()

    def on_steering(self, msg: Any) -> None:
        with self.lock:
            self.steering = max(-1.0, min(1.0, float(msg.data)))
            self.fresh()

    def fresh(self) -> None:
        first = self.last_input_s is None
        self.last_input_s = self.now_s()
        if first or not self.armed:
            self.send(False)  # the arming edge: disengaged, then engaged
            self.armed = True
        self.send(True)  # at once: a ROS command reaches the serial link without waiting a tick

    def send(self, engaged: bool) -> None:
        cmd = self.types.vehicle_command_t()
        cmd.utime = time.time_ns() // 1000
        cmd.seq = self.seq
        self.seq += 1
        cmd.throttle = self.throttle if engaged else 0.0
        cmd.steering = self.steering if engaged else 0.0
        cmd.engaged = engaged
        self.signer.sign(cmd)
        self.lc.publish(self.channel, cmd.encode())
        self.sent += 1

    def tick(self) -> None:
        """Every COMMAND_PERIOD_S: renew while fresh; when quiet, stop, then fall silent."""
        with self.lock:
            self._tick()

    def _tick(self) -> None:
        if self.last_input_s is None:
            return
        if self.now_s() - self.last_input_s <= self.quiet_s:
            self.send(True)
            self.stops_left = STOP_COMMANDS
        elif self.stops_left > 0:
            self.throttle = self.steering = 0.0
            self.send(False)
            self.stops_left -= 1
            self.armed = self.stops_left > 0


class StateBridge:
    """LCM -> ROS: one publisher per topic of autodrive.ros.topics, plus /tf and /tf_static."""

    def __init__(self, m: dict[str, Any], types: Any, cars: list[str], model: CarModel) -> None:
        self.m, self.types, self.model = m, types, model
        rospy = m["rospy"]
        self.rospy = rospy
        self.topics = {t.channel: t for t in topics.state_topics(cars)}
        self.pubs: dict[str, Any] = {}
        self.decode: dict[str, Callable[[bytes, topics.Topic], Any]] = {}
        self.counts: dict[str, int] = {t.topic: 0 for t in self.topics.values()}
        for ch, t in self.topics.items():
            self.pubs[ch] = rospy.Publisher(t.topic, self.ros_class(t.ros_type), queue_size=1000)
        tf = m["tf2_msgs"].TFMessage
        self.tf_pub = rospy.Publisher("/tf", tf, queue_size=1000)
        self.tf_static_pub = rospy.Publisher("/tf_static", tf, queue_size=10, latch=True)
        self.cars = cars
        self.odom: dict[str, tuple[float, float, float]] = {}  # car -> odom pose (x, y, yaw)
        self.sim_time_us: int | None = None
        self.tf_last_us: dict[str, int] = {}  # child frame -> stamp of its newest /tf [us]

    def ros_class(self, ros_type: str) -> Any:
        package, name = ros_type.split("/")
        return getattr(self.m[package], name)

    def stamp(self, utime_us: int) -> Any:
        return self.rospy.Time(utime_us // 1_000_000, (utime_us % 1_000_000) * 1000)

    def header(self, utime_us: int, frame_id: str) -> Any:
        h = self.m["std_msgs"].Header()
        h.stamp = self.stamp(utime_us)
        h.frame_id = frame_id
        return h

    def transform(self, utime_us: int, parent: str, child: str, x: float, y: float, z: float,
                  yaw: float) -> Any:  # fmt: skip
        t = self.m["geometry_msgs"].TransformStamped()
        t.header = self.header(utime_us, parent)
        t.child_frame_id = child
        t.transform.translation.x, t.transform.translation.y, t.transform.translation.z = x, y, z
        q = quaternion_of_yaw(yaw)
        r = t.transform.rotation
        r.x, r.y, r.z, r.w = q
        return t

    def publish_static_tf(self, utime_us: int) -> None:
        tfs = []
        for car in self.cars:
            for child, (x, y, z) in self.model.offsets_m.items():
                tfs.append(self.transform(utime_us, topics.frame(car, "base_link"),
                                          topics.frame(car, child), x, y, z, 0.0))  # fmt: skip
        self.tf_static_pub.publish(self.m["tf2_msgs"].TFMessage(transforms=tfs))

    def handle(self, channel: str, data: bytes) -> None:
        t = self.topics.get(channel)
        if t is None:
            return
        try:
            lcm_msg = getattr(self.types, t.lcm_type).decode(data)
        except ValueError:
            return  # a message that does not decode is not believed (counted by the runtime)
        ros_msg = getattr(self, "from_" + t.lcm_type)(lcm_msg, t)
        self.pubs[channel].publish(ros_msg)
        self.counts[t.topic] += 1

    def from_sim_clock_t(self, s: Any, _t: topics.Topic) -> Any:
        self.sim_time_us = s.utime
        return self.m["rosgraph_msgs"].Clock(clock=self.stamp(s.utime))

    def from_lidar_scan_t(self, s: Any, t: topics.Topic) -> Any:
        r = self.m["sensor_msgs"].LaserScan()
        r.header = self.header(s.utime, topics.frame(t.vehicle, "laser"))
        r.angle_min, r.angle_max, r.angle_increment = (
            s.angle_min_rad, s.angle_max_rad, s.angle_increment_rad
        )  # fmt: skip
        r.time_increment, r.scan_time = s.time_increment_s, s.scan_time_s
        r.range_min, r.range_max = s.range_min_m, s.range_max_m
        r.ranges, r.intensities = list(s.ranges_m), list(s.intensities)
        return r

    def from_imu_t(self, s: Any, t: topics.Topic) -> Any:
        r = self.m["sensor_msgs"].Imu()
        r.header = self.header(s.utime, topics.frame(t.vehicle, "imu_link"))
        w, x, y, z = s.orientation_wxyz
        r.orientation.x, r.orientation.y, r.orientation.z, r.orientation.w = x, y, z, w
        r.orientation_covariance = list(s.orientation_covariance)
        av, la = r.angular_velocity, r.linear_acceleration
        av.x, av.y, av.z = s.angular_velocity_rad_s
        la.x, la.y, la.z = s.linear_acceleration_m_s2
        r.angular_velocity_covariance = list(s.angular_velocity_covariance)
        r.linear_acceleration_covariance = list(s.linear_acceleration_covariance)
        return r

    def odometry(self, utime: int, parent: str, child: str, x: float, y: float, yaw: float,
                 vx: float, vy: float, wz: float) -> Any:  # fmt: skip
        r = self.m["nav_msgs"].Odometry()
        r.header = self.header(utime, parent)
        r.child_frame_id = child
        p = r.pose.pose
        p.position.x, p.position.y = x, y
        p.orientation.x, p.orientation.y, p.orientation.z, p.orientation.w = quaternion_of_yaw(yaw)
        r.twist.twist.linear.x, r.twist.twist.linear.y, r.twist.twist.angular.z = vx, vy, wz
        return r

    def from_odometry_t(self, s: Any, t: topics.Topic) -> Any:
        frame_id = s.frame_id or "odom"
        r = self.odometry(s.utime, topics.frame(t.vehicle, frame_id), topics.frame(t.vehicle, "base_link"),
                          s.x_m, s.y_m, s.yaw_rad, s.vx_m_s, s.vy_m_s, s.yaw_rate_rad_s)  # fmt: skip
        # 6x6 covariances (x y z roll pitch yaw) from the 3x3 (x y yaw) ones
        for src, dst in ((s.pose_covariance, r.pose.covariance), (s.twist_covariance, r.twist.covariance)):  # fmt: skip
            cov = [0.0] * 36
            for i, a in enumerate((0, 1, 5)):
                for j, b in enumerate((0, 1, 5)):
                    cov[6 * a + b] = src[3 * i + j]
            dst[:] = cov
        if t.channel_id == "ODOM":
            self.odom[t.vehicle] = (s.x_m, s.y_m, s.yaw_rad)
            self.publish_tf(s.utime, t.vehicle, "odom", "base_link", (s.x_m, s.y_m, s.yaw_rad))
        elif t.channel_id == "POSE_MAP" and t.vehicle in self.odom:
            self.publish_map_to_odom(s.utime, t.vehicle, (s.x_m, s.y_m, s.yaw_rad))
        return r

    def publish_tf(self, utime: int, car: str, parent: str, child: str,
                   pose: tuple[float, float, float]) -> None:  # fmt: skip
        child_frame = topics.frame(car, child)
        # One transform per stamp and frame: tf2 warns of each repeat (TF_REPEATED_DATA, seen in
        # rviz's log), and an estimator that published a stamp twice (fixed) must not reach it.
        if utime <= self.tf_last_us.get(child_frame, -1):
            return
        self.tf_last_us[child_frame] = utime
        x, y, yaw = pose
        tf = self.transform(utime, topics.frame(car, parent), child_frame, x, y, 0.0, yaw)
        self.tf_pub.publish(self.m["tf2_msgs"].TFMessage(transforms=[tf]))

    def publish_map_to_odom(
        self, utime: int, car: str, map_pose: tuple[float, float, float]
    ) -> None:
        """map -> odom = map -> base_link composed with the inverse of odom -> base_link."""
        ox, oy, oyaw = self.odom[car]
        mx, my, myaw = map_pose
        yaw = myaw - oyaw
        c, s = math.cos(yaw), math.sin(yaw)
        self.publish_tf(
            utime, car, "map", "odom", (mx - (c * ox - s * oy), my - (s * ox + c * oy), yaw)
        )

    def from_ground_truth_t(self, s: Any, t: topics.Topic) -> Any:
        v, w = s.linear_velocity_m_s, s.angular_velocity_rad_s
        x, y, _z = s.position_m
        return self.odometry(s.utime, topics.MAP_FRAME, topics.frame(t.vehicle, "base_link_ground_truth"),
                             x, y, s.yaw_rad, v[0], v[1], w[2])  # fmt: skip

    def from_pose2d_t(self, s: Any, t: topics.Topic) -> Any:
        r = self.m["geometry_msgs"].PoseStamped()
        frame_id = s.frame_id or "map"
        r.header = self.header(
            s.utime, frame_id if frame_id == "map" else topics.frame(t.vehicle, frame_id)
        )
        p = r.pose
        p.position.x, p.position.y = s.x_m, s.y_m
        p.orientation.x, p.orientation.y, p.orientation.z, p.orientation.w = quaternion_of_yaw(
            s.yaw_rad
        )
        return r

    def from_compressed_image_t(self, s: Any, t: topics.Topic) -> Any:
        r = self.m["sensor_msgs"].CompressedImage()
        r.header = self.header(s.utime, topics.frame(t.vehicle, s.frame_id or "camera"))
        r.format, r.data = s.format, bytes(s.data)
        return r

    def from_camera_info_t(self, s: Any, t: topics.Topic) -> Any:
        r = self.m["sensor_msgs"].CameraInfo()
        r.header = self.header(s.utime, topics.frame(t.vehicle, s.frame_id or "camera"))
        r.width, r.height, r.K = s.width_px, s.height_px, list(s.k)
        r.distortion_model, r.D = s.distortion_model, list(s.d)
        k = list(s.k)
        r.P = [k[0], k[1], k[2], 0.0, k[3], k[4], k[5], 0.0, k[6], k[7], k[8], 0.0]
        r.R = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
        return r


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    p = argparse.ArgumentParser(
        prog="autodrive-ros-bridge",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--cars", type=int, default=1, help="cars NIGEL1..NIGELN (default 1)")
    p.add_argument("--lcm-url", default=channels.load().url_default, help="LCM provider")
    p.add_argument("--build", default=None, help="build dir with the generated LCM types "
                   "(default $AUTODRIVE_BUILD, else build/release)")  # fmt: skip
    p.add_argument("--quiet-s", type=float, default=QUIET_S_DEFAULT,
                   help=f"stop the car after this long without a ROS command [s] (default {QUIET_S_DEFAULT})")  # fmt: skip
    p.add_argument(
        "--no-commands", action="store_true", help="bridge the state only (no key needed)"
    )
    p.add_argument("--seconds", type=float, default=0.0,
                   help="stop after this many wall seconds (default: until SIGINT/SIGTERM)")  # fmt: skip
    a = p.parse_args(argv)
    if not 1 <= a.cars <= 32:
        p.error(f"--cars {a.cars}: 1..32")
    if a.quiet_s <= 0:
        p.error(f"--quiet-s {a.quiet_s}: must be > 0")
    return a


def build_dir(arg: str | None) -> str:
    import os

    return arg or os.environ.get("AUTODRIVE_BUILD") or str(settings().preset_build("release"))


def check_master(m: dict[str, Any]) -> None:
    if not m["rosgraph"].is_master_online():
        uri = m["rosgraph"].get_master_uri()
        raise BridgeError(f"no ROS master at {uri} (ROS_MASTER_URI): start roscore first")


def run(a: argparse.Namespace) -> int:
    m = ros_modules()
    check_master(m)
    types = lcmtypes.load(build_dir(a.build))
    cars = [channels.vehicle_name(i) for i in range(1, a.cars + 1)]
    model = car_model()
    lc = lcmtypes.bus(with_receive_buffer(a.lcm_url))
    rospy = m["rospy"]
    rospy.init_node("autodrive_ros_bridge", anonymous=False, disable_signals=False)
    state = StateBridge(m, types, cars, model)

    def now_s() -> float:  # the sim clock while the sim publishes it, else the wall clock
        return state.sim_time_us * 1e-6 if state.sim_time_us is not None else time.monotonic()

    commanders = []
    if not a.no_commands:
        for car in cars:
            try:
                signer = command_auth.signer_for(car, SOURCE)
            except ValueError as e:
                raise BridgeError(str(e)) from None
            commanders.append(Commander(m, types, lc, car, model, signer, a.quiet_s, now_s))
    for ch in state.topics:
        lc.subscribe(ch, state.handle)
    rospy.loginfo("autodrive-ros-bridge: %d topics for %s", len(state.topics), ", ".join(cars))
    t_end = time.monotonic() + a.seconds if a.seconds > 0 else math.inf
    next_tick = time.monotonic()
    next_static = 0.0
    while not rospy.is_shutdown() and time.monotonic() < t_end:
        now = time.monotonic()
        if now >= next_static:
            state.publish_static_tf(state.sim_time_us or time.time_ns() // 1000)
            next_static = now + STATIC_TF_PERIOD_S
        if now >= next_tick:
            for c in commanders:
                c.tick()
            next_tick = max(next_tick + COMMAND_PERIOD_S, now)
        if select.select([lc.fileno()], [], [], max(0.0, min(next_tick, next_static) - now))[0]:
            lc.handle()
    for c in commanders:
        c.throttle = c.steering = 0.0
        if c.last_input_s is not None:
            c.send(False)
    counts = " ".join(f"{k}={v}" for k, v in state.counts.items())
    print(f"autodrive-ros-bridge: published {counts}", file=sys.stderr)
    return 0


def main(argv: list[str] | None = None) -> int:
    # roslaunch appends remappings and __name:=/__log:= arguments: not ours (rospy.myargv)
    a = parse_args([x for x in (sys.argv[1:] if argv is None else argv) if ":=" not in x])
    try:
        return run(a)
    except (BridgeError, RuntimeError, ValueError) as e:
        print(f"autodrive-ros-bridge: ERROR: {e}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
