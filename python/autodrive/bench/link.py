"""tools/bench link: Nano link and estimator figures of the Jetson runtime (issues 5 and 40).
  cmd_to_serial_us_p50, _p99  LCM command -> COMMAND frame on the serial device (fake Nano on
                        a pty); goals <= 500 us and <= 20000 us (one heartbeat period)
  cmd_to_pwm_ms_p50     LCM command -> motor PWM register change (real ELF in nano-simavr),
                        the commands a 50 Hz controller sends; cmd_to_pwm_ms_p50_at_real_time
                        (scaled by simavr's speed) goal <= 5 ms
  serial_cmd_hz_under_flood  COMMAND frames per second on the serial link while 40000 commands a
                        second go to <VEH>_COMMAND (1 in 8 valid); goal <= 1.1 x the token
                        bucket's rate (bridge.command_rate_hz of the car's config)
  flood_cpu_percent     CPU of the bridge process (autodrive-runtime --only bridge) during that
                        flood, per wall second (100 = one core); goal <= FLOOD_CPU_GOAL_PERCENT
  telemetry_hz, telemetry_jitter_ms   <VEH>_STATE on LCM from the real ELF in nano-simavr:
                        the rate in the Nano's clock (its nano_time_us: what the firmware sends
                        and the bridge forwards, whatever speed simavr keeps on a loaded host;
                        telemetry_hz_wall: per wall second); jitter = median |inter-arrival -
                        median inter-arrival| on the host; *_sim: from autodrive-sim
  ekf_pos_rms_m, ekf_heading_rms_deg  <VEH>_POSE_MAP (EKF with Eye poses) vs the simulator's
                        ground truth over a 60 s driven loop; *_no_eye: <VEH>_ODOM (odometry only)
goals_met: every goal above, a missing figure failing its goal. Progress on stderr; the last line
is one JSON object. Usage: tools/bench link [--ekf-seconds S]"""

from __future__ import annotations

import argparse
import os
import subprocess
import tempfile
import time
from pathlib import Path
from typing import Any

import yaml

from autodrive.core.settings import RUNTIME_CAR_CONFIG
from autodrive.core.proc import ProcessGroup
from autodrive.bench import Progress, build_dir, last_json, print_figures
from autodrive.core import seeds
from autodrive.bench.goals import at_least, at_most, judge

UNSEEDED = seeds.unseeded("latencies and rates of fixed runs; the EKF loop is one scripted drive")

PORT_SERIAL, PORT_SIMAVR, PORT_SIM, PORT_FLOOD = 7784, 7785, 7786, 7779
FLOOD_HZ = 40000
# Goals. Latency (issue 40): p99 at most one heartbeat period (20 ms), what every command
# waited by design before issue 40; above the median it is the host's scheduling. The flood's
# CPU cost is the bridge verifying 5000 signed commands a second and dropping 35000 unsigned
# ones. The EKF's (issue 5) with the Eye's poses on.
GOALS = {
    "cmd_to_serial_p50": at_most("cmd_to_serial_us_p50", 500),
    "cmd_to_serial_p99": at_most("cmd_to_serial_us_p99", 20000),
    "cmd_to_pwm": at_most("cmd_to_pwm_ms_p50_at_real_time", 5),
    "flood_cpu": at_most("flood_cpu_percent", 60),
    "serial_cmd_hz_under_flood": at_most("serial_cmd_rate_ratio", 1.1),
    "telemetry_rate": at_least("telemetry_hz", 100),
    "ekf_pos_rms": at_most("ekf_pos_rms_m", 0.03),
    "ekf_heading_rms": at_most("ekf_heading_rms_deg", 2),
}
PTY_WAIT_S = 10.0
SIM_PTY_WAIT_S = 20.0
log = Progress("link")


def url(port: int) -> str:
    return f"udpm://239.255.76.67:{port}?ttl=0"


def runtime_config(path: Path, port: int, device: str) -> Path:
    """The car's config on this port and device, without the LIDAR and camera drivers."""
    cfg = yaml.safe_load(RUNTIME_CAR_CONFIG.read_text())
    cfg["lcm_url"] = url(port)
    cfg["bridge"]["device"] = device
    cfg.pop("lidar", None)
    cfg.pop("cameras", None)
    path.write_text(yaml.safe_dump(cfg, sort_keys=False))
    return path


def flood(build: Path, work: Path, port: int, say: Progress) -> dict[str, Any]:
    """COMMAND frames per second and the bridge's CPU while FLOOD_HZ commands a second go to
    <VEH>_COMMAND (runtime-link-bench flood), against the token bucket's configured rate."""
    cfg = yaml.safe_load(RUNTIME_CAR_CONFIG.read_text())
    rate_hz = float(cfg["bridge"]["command_rate_hz"])
    pty = work / "flood-nano"
    cfg_path = runtime_config(work / "flood.yaml", port, str(pty))
    say(f"flood: {FLOOD_HZ} commands/s on LCM, the bridge against a fake Nano (cap {rate_hz:g} Hz)")
    procs = ProcessGroup(say)
    try:
        bridge = procs.start(
            "autodrive-runtime",
            [build / "bin" / "autodrive-runtime", "--config", cfg_path, "--only", "bridge"]
            + ["--log-level", "warn"],
            work / "flood-runtime.log",
        )
        out = subprocess.run(
            [str(build / "bin" / "runtime-link-bench"), "flood", "--lcm-url", url(port)]
            + ["--pty", str(pty), "--seconds", "10", "--flood-hz", str(FLOOD_HZ)]
            + ["--cpu-pid", str(bridge.pid)],
            check=True,
            stdout=subprocess.PIPE,
            text=True,
        ).stdout
        res = last_json(out, "runtime-link-bench flood")
    finally:
        procs.stop_all()
    res["serial_cmd_hz_configured"] = rate_hz
    res["serial_cmd_rate_ratio"] = round(res["serial_cmd_hz_under_flood"] / rate_hz, 3)
    return res


def wait_for(path: Path, timeout_s: float) -> None:
    t0 = time.monotonic()
    while not path.exists() and time.monotonic() - t0 < timeout_s:
        time.sleep(0.1)


class LinkBench:
    def __init__(self, build: Path, work: Path) -> None:
        self.bin = build / "bin"
        self.work = work

    def measure(self, *args: str) -> dict[str, Any]:
        out = subprocess.run(
            [str(self.bin / "runtime-link-bench"), *args],
            check=True,
            stdout=subprocess.PIPE,
            text=True,
        ).stdout
        return last_json(out, f"runtime-link-bench {args[0]}")

    def runtime(self, procs: ProcessGroup, name: str, port: int, device: Path, only: str) -> None:
        cfg = runtime_config(self.work / f"{name}.yaml", port, str(device))
        argv = [self.bin / "autodrive-runtime", "--config", cfg, "--only", only]
        procs.start(
            "autodrive-runtime", argv + ["--log-level", "warn"], self.work / f"{name}-runtime.log"
        )

    def serial(self) -> dict[str, Any]:
        """LCM -> serial latency against a fake Nano on a pty (the runtime as its own process)."""
        log("cmd_to_serial: autodrive-runtime --only bridge against a pty peer")
        procs = ProcessGroup(log)
        try:
            pty = self.work / "fake-nano"
            self.runtime(procs, "serial", PORT_SERIAL, pty, "bridge")
            return self.measure(
                "serial", "--lcm-url", url(PORT_SERIAL), "--pty", str(pty), "--samples", "500"
            )
        finally:
            procs.stop_all()

    def simavr(self) -> dict[str, Any]:
        """The real ELF in nano-simavr: telemetry rate/jitter and LCM -> PWM register latency."""
        if not os.access(self.bin / "nano-simavr", os.X_OK):
            log("nano-simavr not built: cmd_to_pwm and telemetry from the real ELF not measured")
            return {"cmd_to_pwm_ms_p50": None, "telemetry_hz": None, "telemetry_jitter_ms": None}
        log("nano-simavr: telemetry and cmd_to_pwm")
        procs = ProcessGroup(log)
        try:
            pty, pwm = self.work / "simavr-nano", self.work / "pwm.log"
            procs.start(
                "nano-simavr",
                [self.bin / "nano-simavr", "--pty", pty, "--pwm-log", pwm],
                self.work / "simavr.log",
            )
            wait_for(pty, PTY_WAIT_S)
            self.runtime(procs, "simavr", PORT_SIMAVR, pty, "bridge")
            res = self.measure("telemetry", "--lcm-url", url(PORT_SIMAVR), "--seconds", "10")
            res.update(
                self.measure(
                    "pwm", "--lcm-url", url(PORT_SIMAVR), "--pwm-log", str(pwm), "--samples", "30"
                )
            )
            return res
        finally:
            procs.stop_all()

    def sim(self, ekf_s: float) -> dict[str, Any]:
        """The MuJoCo simulator: telemetry, and the EKF over a driven loop against ground truth."""
        if not os.access(self.bin / "autodrive-sim", os.X_OK):
            log("autodrive-sim not built: EKF figures not measured")
            keys = ("ekf_pos_rms_m", "ekf_heading_rms_deg")
            return {k + s: None for k in keys for s in ("", "_no_eye")}
        log(f"autodrive-sim: telemetry and a {ekf_s:g} s EKF loop")
        procs = ProcessGroup(log)
        try:
            run_dir = self.work / "sim"
            procs.start(
                "autodrive-sim",
                [self.bin / "autodrive-sim", "--run-dir", run_dir, "--lcm-url", url(PORT_SIM)]
                + ["--no-lidar", "--quiet"],
                self.work / "sim.log",
            )
            wait_for(run_dir / "nigel1-nano", SIM_PTY_WAIT_S)
            self.runtime(procs, "sim", PORT_SIM, run_dir / "nigel1-nano", "bridge,estimator")
            res = self.measure(
                "telemetry", "--lcm-url", url(PORT_SIM), "--seconds", "10", "--key-suffix", "_sim"
            )
            res.update(self.measure("ekf", "--lcm-url", url(PORT_SIM), "--seconds", f"{ekf_s:g}"))
            return res
        finally:
            procs.stop_all()


def main(argv: list[str]) -> int:
    p = argparse.ArgumentParser(
        prog="tools/bench link",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "--ekf-seconds", type=float, default=60.0, help="EKF loop length [s] (default 60)"
    )
    a = p.parse_args(argv)
    build = build_dir("link")
    for prog in ("autodrive-runtime", "runtime-link-bench"):
        if not os.access(build / "bin" / prog, os.X_OK):
            log(f"ERROR: {build / 'bin' / prog} missing (build it first)")
            return 1
    with tempfile.TemporaryDirectory(prefix="adr-bench-link.") as work:
        bench = LinkBench(build, Path(work))
        parts = [bench.serial(), flood(build, Path(work), PORT_FLOOD, log), bench.simavr()]
        parts.append(bench.sim(a.ekf_seconds))
    figures: dict[str, Any] = {}
    for part in parts:
        print_figures(part)
        figures.update(part)
    print_figures(judge(figures, GOALS, UNSEEDED))
    return 0
