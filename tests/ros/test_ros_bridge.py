"""The ROS bridge against real ROS (Debian's roscore, rospy, rostopic) and the real HIL stack
(autodrive-sim + the unchanged autodrive-runtime over LCM UDP multicast on loopback):
- every state topic of the car arrives at >= 90 % of its LCM channel's count (lcm-logger's), over one
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
from pathlib import Path

from autodrive.apis import ros_master, stack
from autodrive.apis.ros_probe import RateProbe
from autodrive.core import channels, lcmtypes
from autodrive.ros import topics
from autodrive.ros.bridge import with_receive_buffer

WINDOW_S = (4.0, 6.0)  # the counted window: from 4 s of sim time (or 0.5 s after every
# topic connected), 6 s long [s from the first SIM_CLOCK]
DRIVE_S = (4.0, 9.0)  # Twist published during this sim time [s]
END_S = 13.0  # the test's sim time [s]: quiet from 9 s, stopped well before 13
SIM_SECONDS = 900.0
TWIST_M_S = 0.2
# ROS messages / LCM messages per topic: a broken or stalled bridge is far below. The 95 % goal
# is tools/bench apis's; at load 40 on 2 cores this test saw 0.950 (the bridge and this process
# share the CPU with seven builds), so the test's floor leaves room for CI's load.
MIN_RATIO = 0.90
# The bridged topics every run of this stack publishes (no Eye, no cameras, no v2v, no autonomy).
COUNTED = ("IMU", "LIDAR", "ODOM", "GROUND_TRUTH", "SIM_CLOCK")


def test_no_master_is_a_clear_error() -> None:
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
            ros_master.start(procs, work)
            bridge = [sys.executable, "-m", "autodrive.ros.bridge", "--lcm-url", lcm_url]
            procs.start(
                "autodrive-ros-bridge", bridge + ["--build", build_dir], work / "bridge.log"
            )
            drive_and_count(build_dir, lcm_url, procs, log, work)
        finally:
            exits = procs.stop_all()
            print((work / "bridge.log").read_text()[-3000:])
        assert not [e for e in exits if e.sanitizer_report]


def drive_and_count(build_dir, lcm_url, procs, log, work) -> None:
    import geometry_msgs.msg
    import rospy

    rospy.init_node("autodrive_test", anonymous=True, disable_signals=True)
    car = channels.vehicle_name(1)
    types = lcmtypes.load(build_dir)
    lc = lcmtypes.bus(with_receive_buffer(lcm_url))
    probe = RateProbe(rospy, types, lc, car, COUNTED)
    ref_log = work / "reference.lcmlog"  # the LCM side's counts: lcm-logger keeps up
    logger = ["lcm-logger", f"--lcm-url={lcm_url}", f"--channel={probe.channel_regex()}"]
    logger += ["-f", "--flush-interval=100"]
    procs.start("lcm-logger", logger + [ref_log], work / "lcm-logger.log")
    twist_pub = rospy.Publisher(topics.command_topic(car, "cmd_vel"), geometry_msgs.msg.Twist,
                                queue_size=10)  # fmt: skip
    gt = []  # (utime, x, y, forward speed)
    commands = set()

    def on_gt(_ch, data):
        g = types.ground_truth_t.decode(data)
        gt.append((g.utime, g.position_m[0], g.position_m[1], g.linear_velocity_m_s[0]))

    def on_command(_ch, data):
        c = types.vehicle_command_t.decode(data)
        commands.add((c.source, c.engaged))

    lc.subscribe(channels.channel("GROUND_TRUTH", car), on_gt)
    lc.subscribe(channels.channel("COMMAND", car), on_command)
    # rostopic from the start: it connects while the car drives (the sim ends at SIM_SECONDS)
    echo = subprocess.Popen(["rostopic", "echo", "-n", "1", "--noarr", probe.table["ODOM"].topic],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)  # fmt: skip
    twist = geometry_msgs.msg.Twist()
    twist.linear.x = TWIST_M_S
    next_twist = 0.0
    window = None
    while (t := probe.sim_s()) is None or t < END_S or window is None or t < window[1] + 0.5:
        window = window or probe.window(*WINDOW_S)
        procs.check()
        if select.select([lc.fileno()], [], [], 0.05)[0]:
            lc.handle()
        if t is not None and DRIVE_S[0] <= t < DRIVE_S[1] and t >= next_twist:
            twist_pub.publish(twist)
            next_twist = t + 0.05  # 20 Hz of sim time
    out, err = echo.communicate(timeout=300)  # a hang guard: it printed long before
    probe.close()
    probe.use_lcm_log(str(ref_log))
    log(
        f"whole run: ROS {[len(v) for v in probe.ros.values()]}, LCM {[len(v) for v in probe.lcm.values()]}"
    )
    for k, (n_ros, n_lcm) in probe.counts(*window).items():
        log(
            f"{probe.table[k].topic}: {n_ros} ROS messages / {n_lcm} LCM ({probe.table[k].channel})"
        )
        assert n_lcm > 0, f"no {probe.table[k].channel} on LCM in the window"
        assert n_ros >= MIN_RATIO * n_lcm, f"{probe.table[k].topic}: {n_ros} of {n_lcm}"
    assert 'frame_id: "nigel1/odom"' in out, out + err
    odom = probe.last("ODOM")
    assert (odom.header.frame_id, odom.child_frame_id) == ("nigel1/odom", "nigel1/base_link")
    # the drive: signed commands from source ros, the car moved, and stopped once quiet
    assert ("ros", True) in commands and ("ros", False) in commands, commands
    t0 = probe.first_clock_us
    moved = [g for g in gt if t0 + DRIVE_S[0] * 1e6 <= g[0] <= t0 + DRIVE_S[1] * 1e6 + 1e6]
    dist = math.hypot(moved[-1][1] - moved[0][1], moved[-1][2] - moved[0][2])
    log(f"ground truth: moved {dist:.3f} m under Twist; last speed {gt[-1][3]:.3f} m/s")
    assert dist > 0.3, f"the car moved only {dist:.3f} m under Twist"
    assert abs(gt[-1][3]) < 0.02, f"the car still moves at {gt[-1][3]:.3f} m/s after ROS went quiet"
