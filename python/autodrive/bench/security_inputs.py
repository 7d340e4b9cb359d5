"""The input-checking half of `tools/bench security`: what bad input from the bus does to the
running programs, measured on the real binaries over real LCM (UDP multicast on loopback).

- Eye: wrong-size frames, decompression bombs (a few hundred bytes claiming 20000x20000 px)
  and garbage published on EYE_IMAGE to a running `autodrive-eye run`; counts the times it
  exited, checks it still localises a good frame after each batch, and reads its peak RSS.
- EKF: `autodrive-runtime --only estimator` fed a car standing at (2, 1) m (STATE at 100 Hz)
  with the real Eye at 10 Hz; then a forged <VEH>_POSE_EYE stream at 100 Hz, 1000 m, 10 m and 0.3 m off.
  The jump is the largest POSE_MAP error under the forgery minus the largest before it.
- Log flood: ~2,600 malformed messages/s on each of STATE, IMU and POSE_EYE (plus forged
  poses) to the same runtime; log lines per second per source (channel).
- Fuzz: every libFuzzer target of the build (runtime receive decoders and the firmware
  parser) for fuzz_s seconds each; a crash is a non-zero exit.

run(progress) returns the figures; `python -m autodrive.bench.security_inputs [build]
[--fuzz-s N]` runs it alone (the last stdout line is the JSON object)."""

from __future__ import annotations

import argparse
import io
import math
import os
import random
import re
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from PIL import Image

from autodrive.core import lcmtypes, proc
from autodrive.core.channels import channel, vehicle_name
from autodrive.bench import Progress, print_figures

# Ports: the runtime's test range ends at 7789; 7787 (estimator) and 7793 (Eye) are free there.
RUNTIME_URL = "udpm://239.255.76.67:7787?ttl=0"
EYE_URL = "udpm://239.255.76.67:7793?ttl=0"
VEHICLE = vehicle_name(1)
EYE_POSE_TRUTH = (1.2, 0.9, 0.5)  # NIGEL1 in eye_bench --write-scene's frame.jpg [m, m, rad]
FLOOD_S = 12.0  # longer than the log limiter's 10 s period: its summary line is counted too
FLOOD_RATE_HZ = 2600.0
FUZZ_TARGETS = (
    "tests/runtime/fuzz/fuzz_bridge_rx",
    "tests/runtime/fuzz/fuzz_rplidar",
    "tests/firmware_host/fuzz/fuzz_parser",
)


def peak_rss_mb(pid: int) -> float:
    """VmHWM of a live process [MB] (0 if gone)."""
    try:
        for line in Path(f"/proc/{pid}/status").read_text().splitlines():
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) / 1024.0
    except OSError:
        pass
    return 0.0


def image_bytes(fmt: str, w: int, h: int) -> bytes:
    buf = io.BytesIO()
    Image.new("L", (w, h), 90).save(buf, format=fmt)
    return buf.getvalue()


def jpeg_bomb(w: int, h: int) -> bytes:
    """A tiny real JPEG whose SOF header is patched to claim w x h px."""
    data = bytearray(image_bytes("JPEG", 8, 8))
    for i in range(len(data) - 8):
        if data[i] == 0xFF and data[i + 1] in (0xC0, 0xC2):
            data[i + 5 : i + 9] = bytes([h >> 8, h & 0xFF, w >> 8, w & 0xFF])
            break
    return bytes(data)


class Bus:
    """Publishes and listens on one LCM URL; the handler thread runs while the object lives."""

    def __init__(self, build: Path, url: str) -> None:
        self.types = lcmtypes.load(build)
        self.lc = lcmtypes.bus(url)
        self.stop = False
        self.thread = threading.Thread(target=self._loop, daemon=True)

    def start(self) -> None:
        self.thread.start()

    def _loop(self) -> None:
        while not self.stop:
            self.lc.handle_timeout(50)

    def close(self) -> None:
        self.stop = True
        self.thread.join()


def bench_eye(build: Path, tmp: Path, progress: Callable[[str], None]) -> dict[str, Any]:
    bins = build / "bin"
    subprocess.run(
        [bins / "eye_bench", "--write-scene", tmp, "--lcm-url", EYE_URL],
        check=True,
        capture_output=True,
    )
    frame = (tmp / "frame.jpg").read_bytes()
    bus = Bus(build, f"{EYE_URL}&recv_buf_size=4194304")
    poses: set[int] = set()
    bus.lc.subscribe(
        channel("POSE_EYE", VEHICLE),
        lambda _c, d: poses.add(bus.types.pose2d_t.decode(d).utime),
    )
    bus.start()
    procs = proc.ProcessGroup(progress)

    def start_eye() -> subprocess.Popen[bytes]:
        return procs.start(
            "autodrive-eye",
            [bins / "autodrive-eye", "run", "-c", tmp / "eye.yaml", "--source", "lcm:EYE_IMAGE"]
            + ["-q"],
            tmp / f"eye-{len(procs.items)}.log",
        )

    def send(utime: int, fmt: str, data: bytes) -> None:
        m = bus.types.compressed_image_t()
        m.utime, m.frame_id, m.format = utime, "eye", fmt
        m.width_px, m.height_px, m.size_bytes = 640, 480, len(data)
        m.data = data
        bus.lc.publish(channel("EYE_IMAGE"), m.encode())

    def localises(utime: int, timeout_s: float = 30.0) -> bool:
        t0 = time.monotonic()
        while utime not in poses and time.monotonic() - t0 < timeout_s:
            send(utime, "jpeg", frame)
            time.sleep(0.3)
        return utime in poses

    rng = random.Random(1)
    batches: dict[str, list[tuple[str, bytes]]] = {
        "wrong sizes": [
            ("jpeg", image_bytes("JPEG", 320, 240)),
            ("png", image_bytes("PNG", 1280, 960)),
            ("jpeg", image_bytes("JPEG", 640, 481)),
        ],
        "decompression bombs": [
            ("jpeg", jpeg_bomb(20000, 20000)),
            ("jpeg", jpeg_bomb(65000, 65000)),
        ],
        "garbage": [
            ("jpeg", bytes(rng.randrange(256) for _ in range(335))),
            ("png", bytes(rng.randrange(256) for _ in range(4000))),
            ("bmp", bytes(rng.randrange(256) for _ in range(100))),
            ("jpeg", b""),
            ("jpeg", frame[: len(frame) // 3]),
        ],
    }
    exits, sent, localised_after = 0, 0, 0
    eye = start_eye()
    utime = 1_700_000_000_000_000
    try:
        if not localises(utime):
            raise RuntimeError(f"autodrive-eye never localised the good frame (log in {tmp})")
        for name, frames in batches.items():
            for _ in range(50):
                for fmt, data in frames:
                    utime += 1
                    send(utime, fmt, data)
                    sent += 1
                time.sleep(0.01)
            utime += 1000
            ok = localises(utime)
            if eye.poll() is not None:
                exits += 1
                progress(f"Eye: exited ({eye.returncode}) on {name}; restarting it")
                eye = start_eye()
            localised_after += int(ok)
            progress(f"Eye: {name}: still running, localised the next good frame: {ok}")
        rss_mb = peak_rss_mb(eye.pid)
    finally:
        procs.stop_all()
        bus.close()
    return {
        "eye_exits_on_bad_frames": exits,
        "eye_bad_frames_sent": sent,
        "eye_localised_after_each_batch": localised_after == len(batches),
        "eye_peak_rss_mb": round(rss_mb, 1),
    }


def runtime_config(tmp: Path) -> Path:
    path = tmp / "runtime.yaml"
    path.write_text(
        f'lcm_url: "{RUNTIME_URL}"\nclock: wall\nvehicle: {{name: {VEHICLE}}}\n'
        "estimator: {rate_hz: 100}\n"
    )
    return path


class Drive:
    """A car standing at TRUTH_M: STATE at 100 Hz (encoders still), the real Eye at 10 Hz;
    POSE_MAP errors against the truth are recorded with the phase they fall in."""

    TRUTH_M = (2.0, 1.0)

    def __init__(self, bus: Bus) -> None:
        self.bus = bus
        self.k = 0
        self.errors: list[tuple[str, float]] = []
        self.phase = "honest"
        bus.lc.subscribe(channel("POSE_MAP", VEHICLE), self._on_map)

    def truth(self, utime: int) -> tuple[float, float]:
        return self.TRUTH_M

    def _on_map(self, _c: str, data: bytes) -> None:
        m = self.bus.types.odometry_t.decode(data)
        x, y = self.truth(m.utime)
        self.errors.append((self.phase, math.hypot(m.x_m - x, m.y_m - y)))

    def step(self, forged_offset_m: float | None) -> None:
        t = self.bus.types
        s = t.vehicle_state_t()
        s.utime = 1_000_000 + self.k * 10_000
        s.nano_time_us = self.k * 10_000
        s.encoder_counts = [0, 0]
        self.bus.lc.publish(channel("STATE", VEHICLE), s.encode())
        p = t.pose2d_t()
        p.utime, p.vehicle, p.frame_id, p.yaw_rad = s.utime, VEHICLE, "map", 0.0
        if self.k % 10 == 0:
            p.x_m, p.y_m = self.truth(s.utime)
            self.bus.lc.publish(channel("POSE_EYE", VEHICLE), p.encode())
        if forged_offset_m is not None:
            x, y = self.truth(s.utime)
            p.x_m, p.y_m = x + forged_offset_m, y
            self.bus.lc.publish(channel("POSE_EYE", VEHICLE), p.encode())
        self.k += 1


def start_estimator(
    build: Path, tmp: Path, log: Path, progress: Callable[[str], None]
) -> tuple[Bus, Drive, proc.ProcessGroup]:
    """The bench's bus and driver, and the runtime's estimator alone writing to log."""
    bus = Bus(build, RUNTIME_URL)
    drive = Drive(bus)
    bus.start()
    procs = proc.ProcessGroup(progress)
    cmd = [build / "bin" / "autodrive-runtime", "--config", runtime_config(tmp)]
    procs.start("autodrive-runtime", [*cmd, "--only", "estimator"], log)
    return bus, drive, procs


def bench_estimator(build: Path, tmp: Path, progress: Callable[[str], None]) -> dict[str, Any]:
    log = tmp / "runtime-ekf.log"
    bus, drive, procs = start_estimator(build, tmp, log, progress)
    try:
        time.sleep(1.0)
        for phase, offset, n in (
            ("honest", None, 400),
            ("forged 1000 m", 1000.0, 300),
            ("forged 10 m", 10.0, 300),
            ("forged 0.3 m", 0.3, 300),
        ):
            drive.phase = phase
            progress(f"EKF: {phase}, {n} STATE messages")
            for _ in range(n):
                drive.step(offset)
                time.sleep(0.01)
            procs.check(clean_exit_fails=True)
        time.sleep(0.3)
    finally:
        procs.stop_all()
        bus.close()
    honest = [e for p, e in drive.errors[50:] if p == "honest"]  # after the first fixes
    forged = [e for p, e in drive.errors if p != "honest"]
    if not honest or not forged:
        raise RuntimeError(f"no POSE_MAP from the estimator (log: {log})")
    rejected = len(re.findall(r"Mahalanobis", log.read_text()))
    return {
        "ekf_jump_under_forged_pose_m": round(max(0.0, max(forged) - max(honest)), 4),
        "ekf_max_error_honest_m": round(max(honest), 4),
        "ekf_max_error_forged_m": round(max(forged), 4),
        "ekf_forged_poses_sent": 900,
        "ekf_gate_log_lines": rejected,
    }


def bench_log_flood(build: Path, tmp: Path, progress: Callable[[str], None]) -> dict[str, Any]:
    log = tmp / "runtime-flood.log"
    bus, drive, procs = start_estimator(build, tmp, log, progress)
    sources = [channel(c, VEHICLE) for c in ("STATE", "IMU", "POSE_EYE")]
    rng = random.Random(2)
    garbage = [bytes(rng.randrange(256) for _ in range(rng.randrange(1, 80))) for _ in range(64)]
    sent = 0
    try:
        time.sleep(1.0)
        for _ in range(100):  # a few real messages first: the pose is placed
            drive.step(None)
            time.sleep(0.01)
        lines_before = len(log.read_text().splitlines())
        progress(f"log flood: {FLOOD_RATE_HZ:.0f} malformed messages/s on each of {sources}")
        t0 = time.monotonic()
        period = 1.0 / FLOOD_RATE_HZ
        next_t = t0
        while time.monotonic() - t0 < FLOOD_S:
            for ch in sources:
                bus.lc.publish(ch, garbage[sent % len(garbage)])
                sent += 1
            if sent % 300 == 0:
                drive.step(1000.0)  # and a forged pose now and then
            next_t += period
            delay = next_t - time.monotonic()
            if delay > 0:
                time.sleep(delay)
        elapsed = time.monotonic() - t0
        time.sleep(0.5)
        procs.check(clean_exit_fails=True)
    finally:
        procs.stop_all()
    bus.close()
    lines = log.read_text().splitlines()[lines_before:]
    per_source = {ch: sum(1 for ln in lines if ch in ln) / elapsed for ch in sources}
    progress(f"log flood: {len(lines)} lines in {elapsed:.1f} s for {sent} messages")
    return {
        "log_lines_per_s_under_flood": round(max(per_source.values()), 3),
        "log_lines_per_s_per_source": {k: round(v, 3) for k, v in per_source.items()},
        "flood_messages_per_s": round(sent / elapsed),
        "log_lines_total_under_flood": len(lines),
    }


def bench_fuzz(build: Path, fuzz_s: int, progress: Callable[[str], None]) -> dict[str, Any]:
    crashes, runs = 0, {}
    for rel in FUZZ_TARGETS:
        exe = (build / rel).resolve()
        name = exe.name
        if not exe.is_file():
            raise RuntimeError(f"{exe} is missing (clang-14 and libfuzzer-14-dev build it)")
        with tempfile.TemporaryDirectory() as corpus:
            progress(f"fuzz: {name} for {fuzz_s} s")
            r = subprocess.run(
                [exe, f"-max_total_time={fuzz_s}", "-timeout=5", "-print_final_stats=1", corpus],
                capture_output=True,
                text=True,
                cwd=corpus,
            )
        m = re.search(r"stat::number_of_executed_units:\s*(\d+)", r.stderr)
        runs[name] = int(m.group(1)) if m else 0
        if r.returncode != 0:
            crashes += 1
            progress(f"fuzz: {name} CRASHED:\n{r.stderr[-2000:]}")
    return {"fuzz_crashes": crashes, "fuzz_runs": runs, "fuzz_s_each": fuzz_s}


def run(
    progress: Callable[[str], None], build: Path | None = None, fuzz_s: int = 60
) -> dict[str, Any]:
    """Every figure of the input checks (see the module's doc)."""
    b = (build or Path(os.environ.get("AUTODRIVE_BUILD", ""))).resolve()
    if not (b / "bin" / "autodrive-runtime").is_file():
        raise RuntimeError(f"{b}: no bin/autodrive-runtime (set AUTODRIVE_BUILD or pass the build)")
    figures: dict[str, Any] = {}
    with tempfile.TemporaryDirectory(prefix="adr-security-") as d:
        tmp = Path(d)
        figures.update(bench_eye(b, tmp, progress))
        figures.update(bench_estimator(b, tmp, progress))
        figures.update(bench_log_flood(b, tmp, progress))
    figures.update(bench_fuzz(b, fuzz_s, progress))
    return figures


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        prog="python -m autodrive.bench.security_inputs",
        description="Bad input from the bus against the running Eye and runtime, and the fuzz "
        "targets (the input-checking figures of tools/bench security).",
    )
    ap.add_argument("build", nargs="?", type=Path, help="build dir (default $AUTODRIVE_BUILD)")
    ap.add_argument("--fuzz-s", type=int, default=60, help="seconds per fuzz target")
    a = ap.parse_args(argv)
    figures = run(Progress("security inputs"), a.build, a.fuzz_s)
    print_figures(figures, key_value_lines=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
