"""Capture to pose on LCM: a real `autodrive-eye run --source lcm:EYE_IMAGE` process fed the
wide-angle bench scene (1280x720 JPEG, barrel lens, noise sigma 6, 10 cars, 8 reference tags;
rendered by `eye_bench --write-wide-scene`) at a fixed frame rate over real LCM (UDP
multicast). Each frame is stamped with the system clock when it is published (its capture
time: a camera driver stamps a frame when it has it whole); the time of a frame's pose is when
the LAST of its cars' `<VEH>_POSE_EYE` messages (utime = that capture time) reached the bus: the
kernel's receive time of its datagram on a socket of this process (lcm_wire.WireTap), which
does not wait for this process to be scheduled. So the figure holds the JPEG's trip over UDP,
its decode, detection, pose and the poses' publication. capture_to_pose_read_ms_* is when this
process's LCM handler had read them: that adds a reader's own scheduling (on a 2-core machine
shared with the Eye, ~3 ms in 10 % of frames).

The Eye runs at the lab config's realtime_priority (eye/config/eye.yaml: SCHED_FIFO, as an Eye
machine should run it) unless told otherwise; `tools/bench eye` also times it at ordinary
priority (capture_to_pose_ordinary_*) in the same run.

The first frames (until the Eye has published a pose, plus WARMUP_FRAMES) are not counted: the
Eye's first frame is a whole-frame scan with no car tracked yet. The scene is rendered long
enough for the run (PRE_POSE_FRAMES to spare) and, should the run outlast it, played backwards
from its end, never restarted: a restart would teleport every car at once and time a whole-frame
re-acquisition, which is not what a camera over moving cars sees (the tests of tracking time
that case). The Eye runs with
`detector.threads` 2 unless --threads 1 (the staggered band beside the windows: the latency
path; the one-thread figures are eye_bench's fps_*_1t).

CLI: python -m autodrive.bench.eye_latency <build dir> [frames] [fps]. Run by
`tools/bench eye` (EYE_BENCH_LATENCY_FRAMES, 0: skip) and the test
eye.Latency.CaptureToPoseOnLcm (EYE_LATENCY_PORT picks the LCM port). Progress on stderr;
"key value" lines on stdout. Wall-clock figures: they depend on the machine's load (printed)."""

from __future__ import annotations

import argparse
import contextlib
import os
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any, Iterator

import yaml

from autodrive.core import lcm_wire, lcmtypes, proc
from autodrive.core.channels import channel, vehicle_name
from autodrive.core.settings import EYE_CONFIG
from autodrive.bench import Progress, key_value_main

# eye's port range 7790-7809: 7800 for the benchmark, EYE_LATENCY_PORT=7794 for the test
DEFAULT_PORT = "7800"
CARS = 10  # the wide scene's cars: tag ids 1..10 are NIGEL1..NIGEL10
RECV_BUF_BYTES = 4194304  # the socket also gets the JPEG frames
WARMUP_FRAMES = 10  # one staggered scan cycle (tracking.full_every) after the first pose
PRE_POSE_FRAMES = 30  # frames sent before the Eye's first pose that the scene is rendered for
EYE_IDLE_TIMEOUT_S = 3
FIRST_POSE_TIMEOUT_S = 30.0
DRAIN_S = 1.0  # after the last frame, for its poses to arrive
log = Progress("eye latency")


def percentile(values: list[float], q: float) -> float:
    """The q-quantile (nearest rank, as the Eye's own latency line)."""
    v = sorted(values)
    return v[min(len(v) - 1, int(q * len(v)))]


class PoseTimes:
    """Per capture time [us]: when the last of its poses reached the bus (the kernel's receive
    time of its datagram, lcm_wire.WireTap) and when this process had read it (an LCM
    subscription's handler), both on the system clock [us], and how many poses it got."""

    def __init__(self, url: str, types: Any) -> None:
        self.on_bus: dict[int, int] = {}
        self.read: dict[int, int] = {}
        self.count: dict[int, int] = {}
        self.lock = threading.Lock()
        self.types = types
        self.channels = {channel("POSE_EYE", vehicle_name(k)) for k in range(1, CARS + 1)}
        self.tap = lcm_wire.WireTap(url, self._on_wire, RECV_BUF_BYTES)
        self.lc = lcmtypes.bus(f"{url}&recv_buf_size={RECV_BUF_BYTES}")
        for ch in self.channels:
            self.lc.subscribe(ch, self._on_pose)
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self._pump, daemon=True)
        self.thread.start()

    def _on_wire(self, chan: str, data: bytes, receive_us: int) -> None:
        if chan not in self.channels:
            return
        utime = self.types.pose2d_t.decode(data).utime
        with self.lock:
            self.on_bus[utime] = max(receive_us, self.on_bus.get(utime, 0))
            self.count[utime] = self.count.get(utime, 0) + 1

    def _on_pose(self, _channel: str, data: bytes) -> None:
        now_us = time.time_ns() // 1000
        utime = self.types.pose2d_t.decode(data).utime
        with self.lock:
            self.read[utime] = now_us

    def _pump(self) -> None:
        while not self.stop.is_set():
            self.lc.handle_timeout(20)

    def close(self) -> None:
        self.stop.set()
        self.thread.join()
        self.tap.close()


def cpu_s(pid: int) -> float:
    """User + system CPU time [s] of a running process (/proc/<pid>/stat)."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def image(types: Any, jpeg: bytes, utime: int, w: int, h: int) -> bytes:
    m = types.compressed_image_t()
    m.utime = utime
    m.frame_id = "eye"
    m.format = "jpeg"
    m.width_px, m.height_px = w, h
    m.size_bytes = len(jpeg)
    m.data = jpeg
    return bytes(m.encode())


def scene_index(i: int, n: int) -> int:
    """The i-th frame sent of a scene of n frames played forwards, then backwards, and so on:
    the cars reverse, they never jump."""
    if n < 2:
        return 0
    k = i % (2 * n - 2)
    return k if k < n else 2 * n - 2 - k


@contextlib.contextmanager
def camera_priority(priority: int) -> Iterator[None]:
    """The calling thread (the feeder: the camera's driver) at SCHED_FIFO `priority` while in
    the block, as a camera driver beside a real-time Eye runs; as it was where not permitted."""
    if priority <= 0:
        yield
        return
    try:
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(priority))
    except PermissionError:
        yield
        return
    try:
        yield
    finally:
        os.sched_setscheduler(0, os.SCHED_OTHER, os.sched_param(0))


def feed(
    pub: Any, types: Any, frames: list[bytes], n: int, fps: float, poses: PoseTimes
) -> tuple[list[int], int]:
    """Publishes n frames (`frames` by scene_index) at fps on a fixed schedule, after the Eye's
    first pose and WARMUP_FRAMES more; returns the capture times of the counted frames and the
    number of frames published."""
    ch = channel("EYE_IMAGE")
    period_s = 1.0 / fps
    counted: list[int] = []
    i, t_next = 0, time.monotonic()
    first_pose_deadline = time.monotonic() + FIRST_POSE_TIMEOUT_S
    warm_left = None  # frames still to skip once the Eye has published
    while len(counted) < n:
        t_next += period_s
        utime = time.time_ns() // 1000
        pub.publish(ch, image(types, frames[scene_index(i, len(frames))], utime, 1280, 720))
        i += 1
        if warm_left is None:
            with poses.lock:
                if poses.on_bus:
                    warm_left = WARMUP_FRAMES
            if warm_left is None and time.monotonic() > first_pose_deadline:
                raise RuntimeError(f"no pose from the Eye within {FIRST_POSE_TIMEOUT_S:g} s")
        elif warm_left > 0:
            warm_left -= 1
        else:
            counted.append(utime)
        time.sleep(max(0.0, t_next - time.monotonic()))
    return counted, i


def lab_realtime_priority() -> int:
    """The realtime_priority of the lab's Eye config (eye/config/eye.yaml; 0 when unset)."""
    return int((yaml.safe_load(EYE_CONFIG.read_text()) or {}).get("realtime_priority", 0))


def measure(
    build: Path,
    n_frames: int = 300,
    fps: float = 30.0,
    threads: int = 2,
    realtime_priority: int | None = None,
) -> dict[str, float]:
    """The capture_to_pose_* figures; RuntimeError when the run cannot be measured.
    realtime_priority: the Eye's (None: the lab config's, 0: ordinary scheduling)."""
    if realtime_priority is None:
        realtime_priority = lab_realtime_priority()
    for prog in ("eye_bench", "autodrive-eye"):
        if not os.access(build / "bin" / prog, os.X_OK):
            raise RuntimeError(f"{build / 'bin' / prog} not built")
    url = f"udpm://239.255.76.67:{os.environ.get('EYE_LATENCY_PORT', DEFAULT_PORT)}?ttl=0"
    types = lcmtypes.load(build)
    with tempfile.TemporaryDirectory(prefix="eye-latency-") as tmp_s:
        tmp = Path(tmp_s)
        scene_frames = n_frames + WARMUP_FRAMES + PRE_POSE_FRAMES
        log(f"rendering the wide-angle scene ({scene_frames} frames, 1280x720, 10 cars)")
        subprocess.run(
            [str(build / "bin" / "eye_bench"), "--write-wide-scene", str(tmp)]
            + ["--frames", str(scene_frames), "--lcm-url", url]
            + ["--wide-threads", str(threads)],
            check=True,
            stdout=subprocess.DEVNULL,
        )
        frames = [p.read_bytes() for p in sorted((tmp / "frames").glob("*.jpg"))]
        poses = PoseTimes(url, types)
        eye = subprocess.Popen(
            [str(build / "bin" / "autodrive-eye"), "run", "-c", str(tmp / "eye.yaml")]
            + ["--source", f"lcm:{channel('EYE_IMAGE')}", "-q"]
            + ["--idle-timeout-s", str(EYE_IDLE_TIMEOUT_S)]
            + ["--realtime-priority", str(realtime_priority)],
            stderr=subprocess.PIPE,
            text=True,
        )
        load0 = os.getloadavg()[0]
        cpu0 = time.process_time()
        try:
            pub = lcmtypes.bus(url)
            log(f"feeding {n_frames} frames at {fps:g} Hz (load average {load0:.1f})")
            eye_cpu0 = cpu_s(eye.pid)
            with camera_priority(realtime_priority):
                counted, published = feed(pub, types, frames, n_frames, fps, poses)
            time.sleep(DRAIN_S)
            # the Eye's CPU per frame it was sent, its start-up included [ms]
            eye_cpu_ms = 1000 * (cpu_s(eye.pid) - eye_cpu0) / published
        finally:
            poses.close()
            proc.stop(eye, "autodrive-eye", log)
        eye_err = eye.stderr.read() if eye.stderr else ""
        feeder_cpu_s = time.process_time() - cpu0
    lat_ms, read_ms, missing, short = [], [], 0, 0
    for u in counted:
        if u not in poses.on_bus:
            missing += 1
            continue
        short += poses.count[u] < CARS
        lat_ms.append((poses.on_bus[u] - u) / 1000.0)
        if u in poses.read:
            read_ms.append((poses.read[u] - u) / 1000.0)
        if os.environ.get("EYE_LATENCY_TRACE"):  # per frame, for a look at the slow ones
            print("frame", u, poses.on_bus[u] - u, poses.read.get(u, 0) - u, file=sys.stderr)
    if not lat_ms:
        raise RuntimeError(f"no counted frame got a pose; autodrive-eye said: {eye_err[-1500:]}")
    log(eye_err.strip().splitlines()[-1] if eye_err.strip() else "eye printed nothing")
    return {
        "capture_to_pose_ms_p50": round(percentile(lat_ms, 0.5), 3),
        "capture_to_pose_ms_p99": round(percentile(lat_ms, 0.99), 3),
        "capture_to_pose_ms_max": round(max(lat_ms), 3),
        "capture_to_pose_read_ms_p50": round(percentile(read_ms, 0.5), 3) if read_ms else -1.0,
        "capture_to_pose_read_ms_p99": round(percentile(read_ms, 0.99), 3) if read_ms else -1.0,
        "capture_to_pose_frames": float(len(counted)),
        "capture_to_pose_frames_without_pose": float(missing),
        "capture_to_pose_frames_short_of_10_cars": float(short),
        "capture_to_pose_feed_hz": fps,
        "capture_to_pose_load_avg": round(max(load0, os.getloadavg()[0]), 2),
        "capture_to_pose_feeder_cpu_s": round(feeder_cpu_s, 2),
        "capture_to_pose_eye_cpu_ms_per_frame_sent": round(eye_cpu_ms, 2),
        "capture_to_pose_detector_threads": float(threads),
        # SCHED_FIFO priority the Eye asked for, and whether it got it (1/0)
        "capture_to_pose_realtime_priority": float(realtime_priority),
        "capture_to_pose_realtime_granted": float(
            realtime_priority > 0 and "not granted" not in eye_err
        ),
    }


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(
        prog="python -m autodrive.bench.eye_latency",
        description="Capture to pose on LCM of a running autodrive-eye fed 720p frames with 10 "
        "cars at a fixed rate; prints 'key value' lines (capture_to_pose_*).",
    )
    p.add_argument("build", type=Path, help="host build dir")
    p.add_argument("frames", type=int, nargs="?", default=300, help="frames counted")
    p.add_argument("fps", type=float, nargs="?", default=30.0, help="feed rate [Hz]")
    p.add_argument(
        "--threads",
        type=int,
        choices=(1, 2),
        default=2,
        help="the Eye's detector.threads (2: the staggered band beside the windows)",
    )
    p.add_argument(
        "--realtime-priority",
        type=int,
        default=None,
        help="the Eye's SCHED_FIFO priority (default: eye/config/eye.yaml's; 0: ordinary)",
    )
    a = p.parse_args(argv)
    return key_value_main(
        "eye_latency",
        lambda: measure(a.build, a.frames, a.fps, a.threads, a.realtime_priority),
    )


if __name__ == "__main__":
    sys.exit(main())
