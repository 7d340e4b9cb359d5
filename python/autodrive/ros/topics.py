"""The ROS topic table, derived from the channel table (lcm_types/channels.yaml): nothing here
spells a channel name. A live channel of a car whose LCM type has a standard ROS message becomes
/<car in lower case>/<channel id in lower case> (NIGEL1_LIDAR -> /nigel1/lidar); SIM_CLOCK becomes
/clock. Frames are prefixed with the car (nigel1/base_link) so several cars share one tf tree.
Commands enter on /<car>/cmd_vel (geometry_msgs/Twist) and /<car>/throttle, /<car>/steering
(std_msgs/Float32, the paper's topics), all derived from <VEH>_COMMAND.

`python -m autodrive.ros.topics [--cars N]` prints the table as Markdown (docs/reference)."""

from __future__ import annotations

import argparse
import sys
from dataclasses import dataclass

from autodrive.core import channels

# LCM type -> the standard ROS message it maps to.
ROS_TYPE = {
    "lidar_scan_t": "sensor_msgs/LaserScan",
    "imu_t": "sensor_msgs/Imu",
    "odometry_t": "nav_msgs/Odometry",
    "ground_truth_t": "nav_msgs/Odometry",
    "pose2d_t": "geometry_msgs/PoseStamped",
    "compressed_image_t": "sensor_msgs/CompressedImage",
    "camera_info_t": "sensor_msgs/CameraInfo",
    "sim_clock_t": "rosgraph_msgs/Clock",
}
CLOCK_ID = "SIM_CLOCK"
COMMAND_ID = "COMMAND"
# The command topics per car: (topic suffix, ROS type, what it carries).
COMMAND_TOPICS = (
    ("cmd_vel", "geometry_msgs/Twist", "linear.x [m/s] and angular.z [rad/s] through the car's model"),
    ("throttle", "std_msgs/Float32", "normalised throttle [-1, 1], + forward"),
    ("steering", "std_msgs/Float32", "normalised steering [-1, 1], + left"),
)  # fmt: skip


@dataclass(frozen=True)
class Topic:
    channel: str  # the concrete LCM channel (NIGEL1_LIDAR)
    channel_id: str  # its id in the table (LIDAR)
    topic: str  # the ROS topic (/nigel1/lidar)
    lcm_type: str
    ros_type: str
    vehicle: str  # "" for a channel of the whole bus (SIM_CLOCK)
    rate: str  # the table's nominal rate
    when: str  # the table's condition ("" = every run)


MAP_FRAME = "map"  # the one frame every car shares


def frame(vehicle: str, name: str) -> str:
    """A car's tf frame: nigel1/base_link; the map is everyone's: map."""
    return name if name == MAP_FRAME else f"{vehicle.lower()}/{name}"


def state_topics(vehicles: list[str], table: channels.ChannelTable | None = None) -> list[Topic]:
    """Every bridged LCM -> ROS topic for these cars, in channel-table order."""
    out: list[Topic] = []
    for ch in (table or channels.load()).channels:
        if ch.status != "live" or ch.type not in ROS_TYPE:
            continue
        if ch.id == CLOCK_ID:
            out.append(
                Topic(ch.name, ch.id, "/clock", ch.type, ROS_TYPE[ch.type], "", ch.rate, ch.when)
            )
        elif ch.per_vehicle:
            for v in vehicles:
                topic = f"/{v.lower()}/{ch.id.lower()}"
                out.append(
                    Topic(
                        ch.resolve(v), ch.id, topic, ch.type, ROS_TYPE[ch.type], v, ch.rate, ch.when
                    )
                )
    return out


def command_topic(vehicle: str, suffix: str) -> str:
    """/nigel1/cmd_vel and the like (of <VEH>_COMMAND)."""
    return f"/{vehicle.lower()}/{suffix}"


PATH = "docs/reference/ros-topics.md"
FRAMES = """
Frames (REP-105, one tf tree for every car): `map` -> `<car>/odom` (from `<VEH>_POSE_MAP` and
`<VEH>_ODOM`, when the car knows its map pose) -> `<car>/base_link` (from `<VEH>_ODOM`) ->
`<car>/laser`, `<car>/imu_link`, `<car>/camera_front`, `<car>/camera_rear` (static, from
`vehicle/nigel.params`). The ground truth is `map` -> `<car>/base_link_ground_truth` in its
Odometry message only (not in tf). Stamps are the LCM messages' own: sim time in HIL (use
`/use_sim_time`), wall time on the car.
"""


def render(table: channels.ChannelTable, source: str) -> str:
    """docs/reference/ros-topics.md: the table for car 1, generated from the channel table."""
    car = f"{table.vehicle_prefix}1"
    head = (
        f"<!-- Generated from {source} by autodrive.ros.topics (tools/gen-docs); do not edit. -->\n"
        "# ROS topics\n\n"
        "What `autodrive-ros-bridge` publishes and takes, for car 1 (car N: `/nigelN/...`); "
        "the guide: Guides > ROS 1.\n\n"
    )
    return head + markdown([car], table) + FRAMES


def markdown(vehicles: list[str], table: channels.ChannelTable | None = None) -> str:
    rows = ["| ROS topic | type | from LCM channel | rate | when |", "|---|---|---|---|---|"]
    for t in state_topics(vehicles, table):
        rows.append(
            f"| `{t.topic}` | `{t.ros_type}` | `{t.channel}` | {t.rate} | {t.when or 'always'} |"
        )
    rows += ["", "| ROS command topic | type | carries |", "|---|---|---|"]
    for v in vehicles:
        for suffix, ros_type, what in COMMAND_TOPICS:
            rows.append(f"| `{command_topic(v, suffix)}` | `{ros_type}` | {what} |")
    return "\n".join(rows) + "\n"


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(
        prog="python -m autodrive.ros.topics", description="Print the ROS topic table (Markdown)."
    )
    p.add_argument("--cars", type=int, default=1, help="cars NIGEL1..NIGELN (default 1)")
    a = p.parse_args(argv)
    sys.stdout.write(markdown([channels.vehicle_name(i) for i in range(1, a.cars + 1)]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
