"""The ROS bridge against real ROS (Debian's roscore, rospy, rostopic) and the real HIL stack
(autodrive-sim + the unchanged autodrive-runtime over LCM UDP multicast on loopback):
- every state topic of the car arrives at >= 95 % of its LCM channel's count, counted over one
  window of sim time (message stamps), never a wall deadline;
- `rostopic echo` reads a topic; frames follow the table (nigel1/odom -> nigel1/base_link);
- a rospy node drives the car from geometry_msgs/Twist: signed as source `ros`, the ground truth
  shows it moved; when the ROS side goes quiet the car stops.
The bridge without a ROS master fails with a clear error."""

import math
import os
import select
import subprocess
import sys
import tempfile
import threading
from pathlib import Path

import pytest

from autodrive.apis import ros_master, stack
from autodrive.core import channels, lcmtypes
from autodrive.ros import topics

WINDOW_S = (4.0, 10.0)  # the counted window of sim time [s from the first SIM_CLOCK]
DRIVE_S = (4.0, 9.0)  # Twist published during this sim time [s]
END_S = 13.0  # the test's sim time [s]: quiet from 9 s, stopped well before 13
SIM_SECONDS = 60.0
TWIST_M_S = 0.2
# The bridged topics every run of this stack publishes (no Eye, no cameras, no v2v, no autonomy).
COUNTED = ("IMU", "LIDAR", "ODOM", "GROUND_TRUTH", "SIM_CLOCK")


class Counter:
    """Per key, the stamps [us] seen; thread safe (rospy calls back on its own threads)."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.stamps: dict[str, list[int]] = {}

    def add(self, key: str, utime: int) -> None:
        with self.lock:
            self.stamps.setdefault(key, []).append(utime)

    def in_window(self, key: str, lo_us: int, hi_us: int) -> int:
        with self.lock:
            return sum(lo_us <= t < hi_us for t in self.stamps.get(key, []))


def test_no_master_is_a_clear_error(root: Path) -> None:
    env = dict(os.environ, ROS_MASTER_URI=f"http://127.0.0.1:{ros_master.free_tcp_port()}")
    r = subprocess.run([sys.executable, "-m", "autodrive.ros.bridge"], env=env,
                       capture_output=True, text=True, timeout=120)  # fmt: skip
    assert r.returncode == 1
    assert "no ROS master at http://127.0.0.1:" in r.stderr and "start roscore" in r.stderr


def test_bridge_topics_and_twist_drive(build_dir: Path, lcm_url: str) -> None:
    with tempfile.TemporaryDirectory(prefix="ros-bridge-") as tmp:
        work = Path(tmp)
        os.environ["AUTODRIVE_KEY_DIR"] = str(work / "keys")
        log = lambda msg: print(f"[test] {msg}", flush=True)  # noqa: E731
        procs = stack.start(build_dir, work, lcm_url, log, SIM_SECONDS)
        try:
            run(build_dir, work, lcm_url, procs, log)
        finally:
            exits = procs.stop_all()
            print((work / "bridge.log").read_text()[-3000:] if (work / "bridge.log").exists() else "")
        bad = [e for e in exits if e.sanitizer_report]
        assert not bad, bad


def run(build_dir, work, lcm_url, procs, log) -> None:
    ros_master.start(procs, work)
    bridge = [sys.executable, "-m", "autodrive.ros.bridge", "--lcm-url", lcm_url]
    procs.start("autodrive-ros-bridge", bridge + ["--build", build_dir], work / "bridge.log")
    import geometry_msgs.msg
    import rospy

    rospy.init_node("autodrive_test", anonymous=True, disable_signals=True)
    car = channels.vehicle_name(1)
    table = {t.channel_id: t for t in topics.state_topics([car])}
    ros_count, lcm_count = Counter(), Counter()
    frames: dict[str, tuple[str, str]] = {}
    def on_ros(key):
        def cb(msg):
            stamp = msg.clock if key == "SIM_CLOCK" else msg.header.stamp
            ros_count.add(key, stamp.secs * 1_000_000 + stamp.nsecs // 1000)
            if key == "ODOM":
                frames[key] = (msg.header.frame_id, msg.child_frame_id)
        return cb
    subs = [rospy.Subscriber(table[k].topic, _ros_class(table[k].ros_type),
                             on_ros(k), queue_size=500) for k in COUNTED]  # fmt: skip
    twist_pub = rospy.Publisher(topics.command_topic(car, "cmd_vel"), geometry_msgs.msg.Twist, queue_size=10)

    types = lcmtypes.load(build_dir)
    lc = lcmtypes.bus(lcm_url)
    gt: list[tuple[int, float, float, float]] = []  # (utime, x, y, speed)
    commands: list[tuple[str, bool]] = []
    clock = {"t0": None, "now": None}

    def on_lcm(ch, data):
        key = table_by_channel[ch]
        msg = getattr(types, table[key].lcm_type).decode(data) if key in table else None
        if key == "SIM_CLOCK":
            clock["now"] = msg.utime
            if clock["t0"] is None:
                clock["t0"] = msg.utime
        if key == "GROUND_TRUTH":
            gt.append((msg.utime, msg.position_m[0], msg.position_m[1], msg.linear_velocity_m_s[0]))
        lcm_count.add(key, msg.utime)

    def on_command(_ch, data):
        c = types.vehicle_command_t.decode(data)
        commands.append((c.source, c.engaged))

    table_by_channel = {table[k].channel: k for k in COUNTED}
    for ch in table_by_channel:
        lc.subscribe(ch, on_lcm)
    lc.subscribe(channels.channel("COMMAND", car), on_command)
    twist = geometry_msgs.msg.Twist()
    twist.linear.x = TWIST_M_S
    next_twist = 0
    while True:
        procs.check()
        if select.select([lc.fileno()], [], [], 0.05)[0]:
            lc.handle()
        if clock["t0"] is None:
            continue
        t = (clock["now"] - clock["t0"]) * 1e-6
        if t >= END_S:
            break
        if DRIVE_S[0] <= t < DRIVE_S[1] and t >= next_twist:
            twist_pub.publish(twist)
            next_twist = t + 0.05  # 20 Hz of sim time
    echo = subprocess.run(["rostopic", "echo", "-n", "1", "--noarr", table["ODOM"].topic],
                          capture_output=True, text=True, timeout=120)  # fmt: skip
    for s in subs:
        s.unregister()
    t0 = clock["t0"]
    lo, hi = t0 + int(WINDOW_S[0] * 1e6), t0 + int(WINDOW_S[1] * 1e6)
    for k in COUNTED:
        n_lcm, n_ros = lcm_count.in_window(k, lo, hi), ros_count.in_window(k, lo, hi)
        log(f"{table[k].topic}: {n_ros} ROS messages / {n_lcm} LCM ({table[k].channel})")
        assert n_lcm > 0, f"no {table[k].channel} on LCM in the window"
        assert n_ros >= 0.95 * n_lcm, f"{table[k].topic}: {n_ros} of {n_lcm}"
    assert "frame_id: \"nigel1/odom\"" in echo.stdout, echo.stdout + echo.stderr
    assert frames["ODOM"] == ("nigel1/odom", "nigel1/base_link"), frames
    # the drive: signed commands from source ros, the car moved, and stopped once quiet
    assert ("ros", True) in commands and ("ros", False) in commands, set(commands)
    moved = [g for g in gt if t0 + DRIVE_S[0] * 1e6 <= g[0] <= t0 + DRIVE_S[1] * 1e6 + 1e6]
    dist = math.hypot(moved[-1][1] - moved[0][1], moved[-1][2] - moved[0][2])
    log(f"ground truth: moved {dist:.3f} m under Twist; last speed {gt[-1][3]:.3f} m/s")
    assert dist > 0.3, f"the car moved only {dist:.3f} m under Twist"
    assert abs(gt[-1][3]) < 0.02, f"the car still moves at {gt[-1][3]:.3f} m/s after ROS went quiet"


def _ros_class(ros_type: str):
    import importlib

    package, name = ros_type.split("/")
    return getattr(importlib.import_module(package + ".msg"), name)
