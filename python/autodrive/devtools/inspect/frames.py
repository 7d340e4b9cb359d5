"""What the inspection tools share: which vehicle and table entry a concrete channel is, the
frame names of a vehicle's TF tree, and the map -> odom transform that keeps it a tree."""

from __future__ import annotations

import math
from typing import Any, Optional

from autodrive.core import channels

MAP_FRAME = "map"  # the simulator's world frame is the map's
# base_link -> sensor frames, from the vehicle description's mount keys [m]
SENSOR_MOUNTS = {
    "laser": "lidar_pos_m",
    "imu_link": "imu_pos_m",
    "camera_front": "cam_front_pos_m",
    "camera_rear": "cam_rear_pos_m",
}

Pose2 = tuple[float, float, float]  # x [m], y [m], yaw [rad]


def resolve(table: channels.ChannelTable, concrete: str) -> Optional[tuple[channels.Channel, str]]:
    """The table entry of a concrete channel and its vehicle ('' for channels of no vehicle)."""
    ch = table.match(concrete)
    if ch is None:
        return None
    veh = concrete[: len(concrete) - (len(ch.name) - len(channels.VEH))] if ch.per_vehicle else ""
    return ch, veh


def topic(ch: channels.Channel, veh: str) -> str:
    """/<vehicle>/<id> (/<id> for a channel of no vehicle), in lower case."""
    return "/" + (veh.lower() + "/" if veh else "") + ch.id.lower()


def frame(veh: str, name: str) -> str:
    """A vehicle's frame ('nigel1/base_link'); the map frame is shared by all."""
    return name if name == MAP_FRAME or not veh else f"{veh.lower()}/{name}"


def map_to_odom(map_base: Pose2, odom_base: Pose2) -> Pose2:
    """map_T_odom = map_T_base * inverse(odom_T_base): the transform that makes the odometry's
    base_link land on the map pose, so that base_link keeps one parent (odom) in the TF tree."""
    yaw = map_base[2] - odom_base[2]
    c, s = math.cos(yaw), math.sin(yaw)
    ox, oy = odom_base[0], odom_base[1]
    return map_base[0] - (c * ox - s * oy), map_base[1] - (s * ox + c * oy), yaw


def lcm_fields(msg: Any) -> dict[str, Any]:
    """An LCM message's fields as JSON-able values (bytes as a length: images are not JSON)."""
    out: dict[str, Any] = {}
    for name in msg.__slots__:
        v = getattr(msg, name)
        if isinstance(v, (bytes, bytearray)):
            out[name + "_bytes"] = len(v)
        elif isinstance(v, (list, tuple)):
            out[name] = [x if isinstance(x, (int, float, str, bool)) else str(x) for x in v]
        elif hasattr(v, "__slots__"):
            out[name] = lcm_fields(v)
        else:
            out[name] = v
    return out
