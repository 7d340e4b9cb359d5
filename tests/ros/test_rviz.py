"""Debian's rviz 1.14 under Xvfb with the shipped config ros/autodrive_ros/rviz/nigel.rviz, on the
real HIL stack (autodrive-sim + the unchanged autodrive-runtime over LCM UDP multicast on
loopback, the EKF told the car's start so map -> odom exists), roscore and autodrive-ros-bridge,
/use_sim_time on. It checks that rviz shows data, not only that it started, in event order:
1. rviz subscribed to the scan, the odometry and tf (the master's table);
2. a rospy node drives the car from Twist for 4 s of sim time (it leaves a trail of arrows);
3. once the car stands, a screenshot (ffmpeg x11grab) every 0.5 s of sim time until the 3D view
   holds the scan's magenta squares and the odometry's yellow arrows; then the scan outlines the
   8 m x 8 m walls (its squares span > 6 m at the view's 75 px/m), the arrows lie on the car's
   ground-truth path, rviz's status reads "Global Status: Ok" (tesseract) and rviz logged no
   error or warning.
Wall time is only a hang guard. The last screenshot goes to $AUTODRIVE_SCREENSHOT_DIR when set
(docs/img/ros/rviz-nigel1.png, the ROS guide's picture), else into the build tree."""

from __future__ import annotations

import os
import select
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from autodrive.apis import ros_master, stack
from autodrive.core import channels, lcmtypes
from autodrive.core.proc import ProcessGroup
from autodrive.core.settings import settings
from autodrive.ros import topics

CONFIG = settings().root / "ros" / "autodrive_ros" / "rviz" / "nigel.rviz"
SHOT_NAME = "rviz-nigel1.png"
SCREEN = (1280, 800)  # Xvfb's screen [px]; nigel.rviz's window fills it
SCALE_PX_M = 75.0  # nigel.rviz's TopDownOrtho scale [px/m], centred on the map origin
BACKGROUND = (48, 48, 48)  # nigel.rviz's background colour (RGB) of the 3D view
SIM_SECONDS = 3600.0  # the sim runs until the test stops it (a hang guard)
DRIVE_S = (1.0, 5.0)  # Twist during this sim time after rviz subscribed [s]
FIRST_SHOT_S = 8.0  # the first screenshot at this sim time after rviz subscribed [s]
SHOT_PERIOD_S = 0.5  # of sim time between screenshots [s]
TWIST_M_S = 0.2
GUARD_S = 600.0  # wall-time hang guard of each wait [s]; nothing is judged on it
MIN_SCAN_SPAN_M = 6.0  # the walls are 7.95 m apart; the boxes hide parts of them
MIN_TRAIL_M = 0.4  # the arrows' trail along x [m]; Twist 0.2 m/s for 4 s drives ~0.8 m
PATH_TOL_M = 0.25  # arrows off the ground-truth path [m] (their length is 0.33 m)

pytestmark = pytest.mark.skipif(
    not all(shutil.which(p) for p in ("rviz", "Xvfb", "ffmpeg", "tesseract", "roscore")),
    reason="needs rviz, Xvfb, ffmpeg, tesseract and roscore (tools/debian-packages.txt)",
)


class Bus:
    """The test's view of LCM: the newest SIM_CLOCK [us] and the ground-truth path."""

    def __init__(self, build: Path, url: str) -> None:
        self.types = lcmtypes.load(build)
        self.lc = lcmtypes.bus(url)
        self.clock_us: int | None = None
        self.path: list[tuple[float, float]] = []  # ground truth (x, y) [m] in map
        self.lc.subscribe(channels.channel("SIM_CLOCK"), self._on_clock)
        self.lc.subscribe(channels.channel("GROUND_TRUTH", channels.vehicle_name(1)), self._on_gt)

    def _on_clock(self, _ch: str, data: bytes) -> None:
        self.clock_us = self.types.sim_clock_t.decode(data).utime

    def _on_gt(self, _ch: str, data: bytes) -> None:
        g = self.types.ground_truth_t.decode(data)
        self.path.append((g.position_m[0], g.position_m[1]))

    def sim_s(self) -> float:
        return -1.0 if self.clock_us is None else self.clock_us * 1e-6

    def pump(self, procs: ProcessGroup, until_s: float, tick=None) -> None:
        """Handles LCM until sim time reaches until_s (tick() between messages)."""
        t0 = time.monotonic()
        while self.sim_s() < until_s:
            procs.check()
            assert time.monotonic() - t0 < GUARD_S, f"sim time stuck at {self.sim_s():.2f} s"
            if select.select([self.lc.fileno()], [], [], 0.05)[0]:
                self.lc.handle()
            if tick is not None:
                tick(self.sim_s())


def start_rviz(procs: ProcessGroup, work: Path) -> tuple[str, Path]:
    """Xvfb on a free display, then rviz on nigel.rviz; (display, rviz's log)."""
    display = f":{400 + os.getpid() % 500}"
    procs.start("Xvfb", ["Xvfb", display, "-screen", "0", "{}x{}x24".format(*SCREEN),
                         "-nolisten", "tcp"], work / "xvfb.log")  # fmt: skip
    os.environ["DISPLAY"] = display  # for rviz and ffmpeg, the children that draw or grab
    log = work / "rviz.log"
    procs.start("rviz", ["rviz", "-d", CONFIG], log)
    return display, log


def wait_subscribed(procs: ProcessGroup, bus: Bus) -> float:
    """Sim time [s] once rviz subscribed to the scan, the odometry and tf (the master's table)."""
    import rosgraph

    car = channels.vehicle_name(1)
    want = {t.topic for t in topics.state_topics([car]) if t.channel_id in ("LIDAR", "ODOM")}
    want |= {"/tf", "/tf_static"}
    master = rosgraph.Master("/autodrive_test")
    t0 = time.monotonic()
    while True:
        _pubs, subs, _srvs = master.getSystemState()
        by_rviz = {topic for topic, nodes in subs if any("rviz" in n for n in nodes)}
        if want <= by_rviz:
            return bus.sim_s()
        procs.check()
        assert time.monotonic() - t0 < GUARD_S, f"rviz subscribed only to {sorted(by_rviz)}"
        bus.pump(procs, bus.sim_s() + 0.1)


def twist_publisher(procs: ProcessGroup, bus: Bus):
    """The test's rospy publisher of Twist, once the bridge is connected to it."""
    import geometry_msgs.msg
    import rospy

    rospy.init_node("autodrive_rviz_test", anonymous=True, disable_signals=True)
    pub = rospy.Publisher(topics.command_topic(channels.vehicle_name(1), "cmd_vel"),
                          geometry_msgs.msg.Twist, queue_size=10)  # fmt: skip
    t0 = time.monotonic()
    while pub.get_num_connections() == 0:
        assert time.monotonic() - t0 < GUARD_S, "the bridge never subscribed to cmd_vel"
        bus.pump(procs, bus.sim_s() + 0.1)
    return pub


def drive(procs: ProcessGroup, bus: Bus, pub, t_sub: float) -> None:
    """Twist during DRIVE_S after t_sub, then quiet."""
    import geometry_msgs.msg

    twist = geometry_msgs.msg.Twist()
    twist.linear.x = TWIST_M_S
    due = [t_sub + DRIVE_S[0]]

    def tick(t: float) -> None:
        if t >= due[0] and t < t_sub + DRIVE_S[1]:
            pub.publish(twist)
            due[0] = t + 0.05  # 20 Hz of sim time

    bus.pump(procs, t_sub + DRIVE_S[1], tick)


def grab(display: str, path: Path) -> np.ndarray:
    subprocess.run(["ffmpeg", "-v", "error", "-y", "-f", "x11grab", "-video_size",
                    "{}x{}".format(*SCREEN), "-i", f"{display}+0,0", "-frames:v", "1", str(path)],
                   check=True, timeout=GUARD_S)  # fmt: skip
    return np.asarray(Image.open(path).convert("RGB")).astype(int)


def view_box(img: np.ndarray) -> tuple[int, int, int, int]:
    """The 3D view in the screenshot [px]: x0, y0, x1, y1 of the columns and rows that are
    mostly its background (a few dark pixels of rviz's icons are the same grey)."""
    bg = np.all(img == BACKGROUND, axis=2)
    xs = np.nonzero(bg.mean(axis=0) > 0.3)[0]
    ys = np.nonzero(bg.mean(axis=1) > 0.3)[0]
    return int(xs.min()), int(ys.min()), int(xs.max()), int(ys.max())


def in_map(img: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """(x, y) [m] in map of a mask's pixels inside the 3D view (not rviz's panels): x right, y up
    in the top-down view, whose centre is the map origin."""
    x0, y0, x1, y1 = view_box(img)
    cu, cv = (x0 + x1) / 2.0, (y0 + y1) / 2.0
    ys, xs = np.nonzero(mask[y0 : y1 + 1, x0 : x1 + 1])
    xs, ys = xs + x0, ys + y0
    return np.stack([(xs - cu) / SCALE_PX_M, (cv - ys) / SCALE_PX_M], axis=1)


def scan_and_arrows(img: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Map points [m] of the scan's magenta squares (flat colour) and the yellow arrows (lit)."""
    r, g, b = img[..., 0], img[..., 1], img[..., 2]
    scan = (r == 255) & (g == 0) & (b == 255)
    arrows = (r > 150) & (g > 150) & (b < 60)
    return in_map(img, scan), in_map(img, arrows)


def shown(img: np.ndarray) -> bool:
    scan, arrows = scan_and_arrows(img)
    return len(scan) > 50 and len(arrows) > 20


def wait_shown(procs: ProcessGroup, bus: Bus, display: str, shot: Path, t0: float) -> np.ndarray:
    """Screenshots every SHOT_PERIOD_S of sim time from t0 until the scan and arrows show."""
    t_wall = time.monotonic()
    t = t0
    while True:
        bus.pump(procs, t)
        img = grab(display, shot)
        if shown(img) or time.monotonic() - t_wall > GUARD_S:
            return img
        t = bus.sim_s() + SHOT_PERIOD_S


def status_text(img_path: Path, work: Path) -> str:
    """tesseract's reading of the Displays panel (left of the 3D view), 2x larger."""
    panel = Image.open(img_path).convert("L").crop((0, 60, 360, 240))
    big = work / "status.png"
    panel.resize((panel.width * 2, panel.height * 2), Image.LANCZOS).save(big)
    r = subprocess.run(["tesseract", str(big), "stdout"], capture_output=True, text=True,
                       timeout=GUARD_S)  # fmt: skip
    return r.stdout


def check_picture(img: np.ndarray, path: list[tuple[float, float]]) -> None:
    scan, arrows = scan_and_arrows(img)
    assert len(scan) > 50, f"rviz shows no scan: {len(scan)} magenta px"
    assert len(arrows) > 20, f"rviz shows no odometry: {len(arrows)} yellow px"
    span = scan.max(axis=0) - scan.min(axis=0)
    print(f"[test] scan spans {span[0]:.2f} m x {span[1]:.2f} m; {len(arrows)} arrow px")
    assert min(span) > MIN_SCAN_SPAN_M, f"the scan spans only {span} m: not the walls"
    trail = arrows[:, 0].max() - arrows[:, 0].min()
    assert trail > MIN_TRAIL_M, f"the arrows' trail is {trail:.2f} m long"
    gt = np.array(path)
    off = np.abs(arrows[:, 1] - gt[:, 1].mean()).max()
    print(f"[test] arrows' trail {trail:.2f} m, at most {off:.3f} m off the ground-truth line")
    assert off < PATH_TOL_M, f"the arrows lie {off:.3f} m off the car's path (y)"
    x0, x1 = gt[:, 0].min() - PATH_TOL_M, gt[:, 0].max() + 0.33 + PATH_TOL_M
    assert x0 <= arrows[:, 0].min() and arrows[:, 0].max() <= x1, (arrows[:, 0].min(), x0, x1)


def check_log(log: Path) -> None:
    """No rosconsole error or warning (rospack's note about media_export is not one)."""
    text = log.read_text(errors="replace")
    bad = [ln for ln in text.splitlines() if "[ERROR]" in ln or "[ WARN]" in ln]
    assert not bad, "rviz logged:\n" + "\n".join(bad[:20])


def keep(shot: Path, build: Path) -> None:
    out = Path(os.environ.get("AUTODRIVE_SCREENSHOT_DIR", build))
    shutil.copy(shot, out / SHOT_NAME)
    print(f"[test] screenshot: {out / SHOT_NAME}")


def test_rviz_shows_scan_and_car(build_dir: Path, lcm_url: str) -> None:
    with tempfile.TemporaryDirectory(prefix="ros-rviz-") as tmp:
        work = Path(tmp)
        os.environ["AUTODRIVE_KEY_DIR"] = str(work / "keys")
        log = lambda msg: print(f"[test] {msg}", flush=True)  # noqa: E731
        procs = stack.start(build_dir, work, lcm_url, log, SIM_SECONDS, map_pose=True)
        try:
            ros_master.start(procs, work)
            subprocess.run(["rosparam", "set", "/use_sim_time", "true"], check=True,
                           timeout=GUARD_S)  # fmt: skip
            bridge = [sys.executable, "-m", "autodrive.ros.bridge", "--lcm-url", lcm_url]
            procs.start("autodrive-ros-bridge", bridge + ["--build", build_dir],
                        work / "bridge.log")  # fmt: skip
            bus = Bus(build_dir, lcm_url)
            display, rviz_log = start_rviz(procs, work)
            pub = twist_publisher(procs, bus)
            t_sub = wait_subscribed(procs, bus)
            log(f"rviz subscribed at sim time {t_sub:.2f} s")
            drive(procs, bus, pub, t_sub)
            shot = work / SHOT_NAME
            img = wait_shown(procs, bus, display, shot, t_sub + FIRST_SHOT_S)
            log(f"screenshot at sim time {bus.sim_s():.2f} s")
            keep(shot, build_dir)
            check_picture(img, bus.path)
            text = status_text(shot, work)
            assert "Global Status: Ok" in text, f"rviz's status panel reads:\n{text}"
            check_log(rviz_log)
        finally:
            exits = procs.stop_all()
        assert not [e for e in exits if e.sanitizer_report]
