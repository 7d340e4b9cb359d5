"""ROS 2 message definitions (the .msg text of the ROS 2 interfaces, as MCAP's ros2msg schema
encoding wants it: the message, then each type it uses after a separator line), so that a run
opens in Foxglove and in `ros2 bag` without a ROS installation."""

from __future__ import annotations

SEPARATOR = "=" * 80

# Each interface's own fields; dependencies are appended by definition().
_FIELDS: dict[str, str] = {
    "builtin_interfaces/Time": "int32 sec\nuint32 nanosec",
    "std_msgs/Header": "builtin_interfaces/Time stamp\nstring frame_id",
    "geometry_msgs/Point": "float64 x\nfloat64 y\nfloat64 z",
    "geometry_msgs/Vector3": "float64 x\nfloat64 y\nfloat64 z",
    "geometry_msgs/Quaternion": "float64 x\nfloat64 y\nfloat64 z\nfloat64 w",
    "geometry_msgs/Pose": "geometry_msgs/Point position\ngeometry_msgs/Quaternion orientation",
    "geometry_msgs/PoseStamped": "std_msgs/Header header\ngeometry_msgs/Pose pose",
    "geometry_msgs/PoseWithCovariance": "geometry_msgs/Pose pose\nfloat64[36] covariance",
    "geometry_msgs/Twist": "geometry_msgs/Vector3 linear\ngeometry_msgs/Vector3 angular",
    "geometry_msgs/TwistWithCovariance": "geometry_msgs/Twist twist\nfloat64[36] covariance",
    "geometry_msgs/Transform": (
        "geometry_msgs/Vector3 translation\ngeometry_msgs/Quaternion rotation"
    ),
    "geometry_msgs/TransformStamped": (
        "std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/Transform transform"
    ),
    "tf2_msgs/TFMessage": "geometry_msgs/TransformStamped[] transforms",
    "sensor_msgs/LaserScan": (
        "std_msgs/Header header\nfloat32 angle_min\nfloat32 angle_max\nfloat32 angle_increment\n"
        "float32 time_increment\nfloat32 scan_time\nfloat32 range_min\nfloat32 range_max\n"
        "float32[] ranges\nfloat32[] intensities"
    ),
    "sensor_msgs/Imu": (
        "std_msgs/Header header\ngeometry_msgs/Quaternion orientation\n"
        "float64[9] orientation_covariance\ngeometry_msgs/Vector3 angular_velocity\n"
        "float64[9] angular_velocity_covariance\ngeometry_msgs/Vector3 linear_acceleration\n"
        "float64[9] linear_acceleration_covariance"
    ),
    "sensor_msgs/CompressedImage": "std_msgs/Header header\nstring format\nuint8[] data",
    "nav_msgs/Odometry": (
        "std_msgs/Header header\nstring child_frame_id\n"
        "geometry_msgs/PoseWithCovariance pose\ngeometry_msgs/TwistWithCovariance twist"
    ),
    "nav_msgs/Path": "std_msgs/Header header\ngeometry_msgs/PoseStamped[] poses",
    "nav_msgs/MapMetaData": (
        "builtin_interfaces/Time map_load_time\nfloat32 resolution\nuint32 width\n"
        "uint32 height\ngeometry_msgs/Pose origin"
    ),
    "nav_msgs/OccupancyGrid": "std_msgs/Header header\nnav_msgs/MapMetaData info\nint8[] data",
}


def _uses(name: str) -> list[str]:
    """The interfaces a definition's fields name, in order of first use, recursively."""
    out: list[str] = []
    for line in _FIELDS[name].splitlines():
        field_type = line.split()[0].split("[")[0]
        if "/" in field_type and field_type not in out:
            out.append(field_type)
            out += [u for u in _uses(field_type) if u not in out]
    return out


def ros2_type(name: str) -> str:
    """'sensor_msgs/LaserScan' -> 'sensor_msgs/msg/LaserScan' (the schema name ROS 2 uses)."""
    package, message = name.split("/")
    return f"{package}/msg/{message}"


def definition(name: str) -> str:
    """The full ros2msg schema text of an interface, with its dependencies."""
    parts = [_FIELDS[name]]
    for dep in _uses(name):
        parts.append(f"{SEPARATOR}\nMSG: {dep}\n{_FIELDS[dep]}")
    return "\n".join(parts) + "\n"


def names() -> list[str]:
    return sorted(_FIELDS)
