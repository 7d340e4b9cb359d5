"""eye.Sim.LockstepDoesNotDependOnTheEyesSpeed: `autodrive-sim --lockstep --eye --eye-sync` (a
scripted car under Parking School's overhead camera) with `autodrive-eye run --sim-latency-ms
20`, once as it is and once slowed by `--cpu-delay-ms 60` (a test double: an Eye slower than
the frame period). Each run records every NIGEL1_POSE_EYE with the SIM_CLOCK the bus had when
the pose arrived. Both runs give the same poses (stamps and values), each arriving at exactly
its capture time + 20 ms of sim time, and the same ground truth bytes: how fast the Eye is in
wall time changes nothing in sim time. Judged on sim time and event order only (the only wall
clock is the give-up rule, 10 s, which a passing run never reaches)."""

from __future__ import annotations

import os
import subprocess
import threading
from pathlib import Path
from typing import Any

from autodrive.bench.eye_sim import CAR_SCRIPT, VEHICLE, write_eye_config
from autodrive.core import lcmtypes
from autodrive.core.channels import channel

PORT = os.environ.get("EYE_LOCKSTEP_PORT", "7807")
URL = f"udpm://239.255.76.67:{PORT}?ttl=0"
RECV_BUF_BYTES = 4194304  # the socket also gets the JPEG frames
LATENCY_MS = 20
SLOW_MS = 50  # more than the 33 ms frame period: in wall time the slow Eye falls behind
DURATION_S = 1.0
Pose = tuple[int, float, float, float, int]  # utime, x, y, yaw, SIM_CLOCK at arrival [us]


class Bus:
    """Every Eye pose with the newest SIM_CLOCK before it, and EYE_FRAME_DONE, on a thread."""

    def __init__(self, build: Path) -> None:
        types = lcmtypes.load(build)
        self.clock_us = -1
        self.poses: list[Pose] = []
        self.done: list[int] = []
        self.lc = lcmtypes.bus(f"{URL}&recv_buf_size={RECV_BUF_BYTES}")
        self.lc.subscribe(channel("SIM_CLOCK"), lambda _c, d: self._clock(types.sim_clock_t, d))
        self.lc.subscribe(channel("POSE_EYE", VEHICLE), lambda _c, d: self._pose(types.pose2d_t, d))
        self.lc.subscribe(channel("EYE_FRAME_DONE"), lambda _c, d: self._done(types, d))
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self._pump, daemon=True)
        self.thread.start()

    def _clock(self, typ: Any, data: bytes) -> None:
        self.clock_us = max(self.clock_us, typ.decode(data).utime)

    def _pose(self, typ: Any, data: bytes) -> None:
        p = typ.decode(data)
        self.poses.append((p.utime, p.x_m, p.y_m, p.yaw_rad, self.clock_us))

    def _done(self, types: Any, data: bytes) -> None:
        utime = types.eye_frame_done_t.decode(data).utime
        if utime >= 0:  # -1: "ready", said as often as wall time allows
            self.done.append(utime)

    def _pump(self) -> None:
        while not self.stop.is_set():
            self.lc.handle_timeout(50)

    def close(self) -> None:
        self.stop.set()
        self.thread.join()


def run(build: Path, tmp: Path, slow_ms: int) -> tuple[list[Pose], bytes, list[int]]:
    """One run: the Eye (slowed by slow_ms of CPU per frame), then the sim; what the bus saw."""
    tmp.mkdir()
    bus = Bus(build)
    eye = subprocess.Popen(
        [str(build / "bin" / "autodrive-eye"), "run", "-c", str(write_eye_config(tmp, URL))]
        + ["--source", f"lcm:{channel('EYE_IMAGE')}", "--sim-latency-ms", str(LATENCY_MS)]
        + ["--cpu-delay-ms", str(slow_ms), "--idle-timeout-s", "5", "-q"],
        stderr=subprocess.PIPE,
        text=True,
    )
    truth = tmp / "truth.bin"
    try:
        sim = subprocess.run(
            [str(build / "bin" / "autodrive-sim"), "--lockstep", "--no-pty", "--no-lidar"]
            + ["--eye", "--eye-sync", "--script", CAR_SCRIPT, "--duration", str(DURATION_S)]
            + ["--lcm-url", URL, "--run-dir", str(tmp / "run"), "--truth-log", str(truth)],
            capture_output=True,
            text=True,
            timeout=900,
        )
        _, eye_err = eye.communicate(timeout=120)
    finally:
        if eye.poll() is None:
            eye.kill()
        bus.close()
    print(sim.stderr[-1500:], eye_err[-1500:])
    assert sim.returncode == 0, f"autodrive-sim exited {sim.returncode}"
    assert eye.returncode == 0, f"autodrive-eye exited {eye.returncode}"
    assert "gave it up 0 time(s)" in sim.stderr, "the sim gave up on the Eye"
    return bus.poses, truth.read_bytes(), bus.done


def test_lockstep_does_not_depend_on_the_eyes_speed(build_dir: Path, tmp_path: Path) -> None:
    fast, truth_fast, done_fast = run(build_dir, tmp_path / "fast", 0)
    slow, truth_slow, done_slow = run(build_dir, tmp_path / "slow", SLOW_MS)
    frames = int(DURATION_S * 30)
    assert len(fast) >= frames - 2, f"{len(fast)} poses for {frames} frames"
    # a frame whose release falls after the run's end goes out when the Eye gives up on the
    # stopped clock (the sim is gone): not part of the run
    end_us = round(DURATION_S * 1e6)
    fast = [p for p in fast if p[0] + 1000 * LATENCY_MS <= end_us]
    slow = [p for p in slow if p[0] + 1000 * LATENCY_MS <= end_us]
    done_fast = [t for t in done_fast if t + 1000 * LATENCY_MS <= end_us]
    done_slow = [t for t in done_slow if t + 1000 * LATENCY_MS <= end_us]
    late = [(p[0], p[4]) for p in fast + slow if p[4] != p[0] + 1000 * LATENCY_MS]
    assert not late, f"poses not on the bus at capture + {LATENCY_MS} ms (utime, clock): {late[:5]}"
    assert fast == slow, "the slowed Eye's poses differ (stamps, values or arrival)"
    assert done_fast == done_slow, "the frames done differ"
    assert truth_fast == truth_slow, "the ground truth differs"
    print(f"PASS: {len(fast)} poses, each at capture + {LATENCY_MS} ms of sim time, in both runs")
