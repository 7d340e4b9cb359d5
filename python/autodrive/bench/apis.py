"""tools/bench apis: the ROS and MATLAB/Octave APIs (issue 37) on the real HIL stack
(autodrive-sim + the unchanged autodrive-runtime on LCM UDP multicast, release build).
  ros_rate_ratio.<id>     messages on the bridged ROS topic / on its LCM channel, both counted by
                          their stamps over one window of sim time; goal >= 0.95 each
  ros_cmd_to_lcm_us_p50   a std_msgs/Float32 on /<car>/throttle -> its signed <VEH>_COMMAND on
                          LCM (the bridge's path), wall clock of this process
  cmd_to_serial_us_p50    <VEH>_COMMAND -> its COMMAND frame on the serial device (the bridge
                          against a fake Nano on a pty: runtime-link-bench serial)
  ros_cmd_to_serial_us_p50  the sum of the two medians above (two legs measured in this run)
  octave_state_hz         NIGEL1_STATE messages Octave received per second of their stamps (sim
                          time); goal >= 95 (95 % of 100 Hz)
  octave_cmd_to_lcm_us_p50  Octave's autodrive.Car command (stamped before signing) -> on LCM
  octave_cmd_to_serial_us_p50  its sum with cmd_to_serial_us_p50
goals_met: every goal above, a missing figure failing its goal. Progress on stderr; the last line
is one JSON object. Usage: tools/bench apis [--window-s S]"""

from __future__ import annotations

import argparse
import os
import select
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

from autodrive.apis import octave, ros_master, stack
from autodrive.apis.ros_probe import RateProbe
from autodrive.bench import Progress, build_dir, last_json, print_figures
from autodrive.bench.goals import Goal, at_least, at_most, judge
from autodrive.bench.link import LinkBench
from autodrive.core import channels, lcmtypes, seeds
from autodrive.ros.bridge import with_receive_buffer

UNSEEDED = seeds.unseeded("rates and latencies of fixed runs on the HIL stack")
PORT = 7964
RATE_IDS = ("IMU", "LIDAR", "ODOM", "GROUND_TRUTH", "SIM_CLOCK")
GOALS: dict[str, Goal] = {
    f"ros_rate_{k.lower()}": at_least(f"ros_rate_ratio.{k}", 0.95) for k in RATE_IDS
}
GOALS["octave_state_rate"] = at_least("octave_state_hz", 95)
# Latency goals: a command from ROS or Octave reaches the serial link within one heartbeat
# period (20 ms), the bound the C++ sources' p99 meets (tools/bench link).
GOALS["ros_cmd_to_serial"] = at_most("ros_cmd_to_serial_us_p50", 20000)
GOALS["octave_cmd_to_serial"] = at_most("octave_cmd_to_serial_us_p50", 20000)
SIM_SECONDS = 600.0
LATENCY_SAMPLES = 200
OCTAVE_GUARD_S = 900.0
log = Progress("apis")


class CommandWatch(threading.Thread):
    """Arrival wall time [us] and content of every <VEH>_COMMAND, off its own LCM instance."""

    def __init__(self, types: Any, url: str, car: str) -> None:
        super().__init__(daemon=True)
        self.types, self.lc = types, lcmtypes.bus(with_receive_buffer(url))
        self.lc.subscribe(channels.channel("COMMAND", car), self.on_command)
        self.seen: list[tuple[int, Any]] = []
        self.lock = threading.Lock()
        self.stop = False

    def on_command(self, _ch: str, data: bytes) -> None:
        now_us = time.time_ns() // 1000
        with self.lock:
            self.seen.append((now_us, self.types.vehicle_command_t.decode(data)))

    def run(self) -> None:
        while not self.stop:
            if select.select([self.lc.fileno()], [], [], 0.1)[0]:
                self.lc.handle()

    def first(self, source: str, throttle: float, after_us: int) -> int | None:
        with self.lock:
            for t, c in self.seen:
                if (
                    t >= after_us
                    and c.source == source
                    and c.engaged
                    and abs(c.throttle - throttle) < 1e-4
                ):
                    return t
        return None


def ros_part(
    build: Path, url: str, types: Any, window_s: float, watch: CommandWatch
) -> dict[str, Any]:
    import rospy
    import std_msgs.msg

    rospy.init_node("autodrive_bench", anonymous=True, disable_signals=True)
    car = channels.vehicle_name(1)
    lc = lcmtypes.bus(with_receive_buffer(url))
    probe = RateProbe(rospy, types, lc, car, RATE_IDS)
    log(f"ROS rates: counting {window_s:g} s of sim time")
    window = None
    while (t := probe.sim_s()) is None or window is None or t < window[1] + 1.0:
        window = window or probe.window(3.0, window_s)
        if select.select([lc.fileno()], [], [], 0.1)[0]:
            lc.handle()
    probe.close()
    counts = probe.counts(*window)
    ratios = {k: round(r / n, 4) if n else None for k, (r, n) in counts.items()}
    log(f"ROS rates: {counts}")
    pub = rospy.Publisher(f"/{car.lower()}/throttle", std_msgs.msg.Float32, queue_size=10)
    time.sleep(1.0)  # the bridge's subscriber connects (ROS topic negotiation)
    lat = []
    for k in range(LATENCY_SAMPLES):
        value = round(0.1 + 0.001 * (k % 300), 3)
        t0 = time.time_ns() // 1000
        pub.publish(std_msgs.msg.Float32(data=value))
        while (
            t1 := watch.first("ros", value, t0)
        ) is None and time.time_ns() // 1000 - t0 < 2_000_000:
            time.sleep(0.0002)
        if t1 is not None:
            lat.append(t1 - t0)
        time.sleep(0.03)
    log(f"ROS command -> LCM: {len(lat)} of {LATENCY_SAMPLES} samples")
    return {
        "ros_rate_ratio": ratios,
        "ros_counts": {k: {"ros": r, "lcm": n} for k, (r, n) in counts.items()},
        "ros_cmd_to_lcm_us_p50": statistics.median(lat) if lat else None,
        "ros_cmd_samples": len(lat),
    }


OCTAVE_SCRIPT = """
lc = autodrive.connect();
state = autodrive.subscribe(lc, autodrive.channel('STATE', 'NIGEL1'));
n = 0; first = []; last = [];
while isempty(first) || double(last - first) < {window_s} * 1e6
  m = autodrive.next(state, 30);
  if isempty(m), error('no NIGEL1_STATE within 30 s'); end
  if isempty(first), first = m.utime; end
  last = m.utime; n = n + 1;
end
car = autodrive.Car(lc, 'NIGEL1');
for k = 1:{samples}
  car.drive(0.1 + 0.001 * mod(k, 300), 0);
  pause(0.03);
end
car.release();
printf('{{"octave_state_count": %d, "octave_state_span_s": %.6f}}\\n', n, double(last - first) * 1e-6);
"""


def octave_part(build: Path, url: str, window_s: float, watch: CommandWatch) -> dict[str, Any]:
    log(f"Octave: NIGEL1_STATE over {window_s:g} s of sim time, then {LATENCY_SAMPLES} commands")
    t_start = time.time_ns() // 1000
    script = OCTAVE_SCRIPT.format(window_s=window_s, samples=LATENCY_SAMPLES)
    r = octave.run(build, url, script, OCTAVE_GUARD_S)
    if r.returncode != 0:
        log(f"Octave failed: {r.stderr[-500:]}")
        return {"octave_state_hz": None, "octave_cmd_to_lcm_us_p50": None}
    res = last_json(r.stdout, "octave")
    with watch.lock:
        lat = [
            t - c.utime
            for t, c in watch.seen
            if c.source == "octave" and c.engaged and t >= t_start
        ]
    # Octave counted n messages over the span between its first and last stamp: n - 1 periods.
    hz = (
        (res["octave_state_count"] - 1) / res["octave_state_span_s"]
        if res["octave_state_span_s"] > 0
        else None
    )
    return {
        **res,
        "octave_state_hz": round(hz, 2) if hz else None,
        "octave_cmd_to_lcm_us_p50": statistics.median(lat) if lat else None,
        "octave_cmd_samples": len(lat),
    }


def serial_leg(build: Path, work: Path) -> dict[str, Any]:
    """<VEH>_COMMAND -> serial frame: runtime-link-bench serial (the bridge, a fake Nano)."""
    if not os.access(build / "bin" / "runtime-link-bench", os.X_OK):
        log("runtime-link-bench not built: cmd_to_serial not measured")
        return {"cmd_to_serial_us_p50": None}
    return LinkBench(build, work).serial()


def add(a: Any, b: Any) -> float | None:
    return round(a + b, 1) if isinstance(a, (int, float)) and isinstance(b, (int, float)) else None


def main(argv: list[str]) -> int:
    p = argparse.ArgumentParser(prog="tools/bench apis", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)  # fmt: skip
    p.add_argument("--window-s", type=float, default=10.0, help="sim-time window of the rates [s]")
    a = p.parse_args(argv)
    build = build_dir("apis")
    url = f"udpm://239.255.76.67:{PORT}?ttl=0"
    figures: dict[str, Any] = {"load_1min": round(os.getloadavg()[0], 1)}
    with tempfile.TemporaryDirectory(prefix="adr-bench-apis.") as tmp:
        work = Path(tmp)
        os.environ.setdefault("AUTODRIVE_KEY_DIR", str(work / "keys"))
        types = lcmtypes.load(build)
        watch = CommandWatch(types, url, channels.vehicle_name(1))
        watch.start()
        procs = stack.start(build, work, url, log, SIM_SECONDS)
        try:
            ros_master.start(procs, work)
            bridge = [
                sys.executable,
                "-m",
                "autodrive.ros.bridge",
                "--lcm-url",
                url,
                "--build",
                build,
            ]
            procs.start("autodrive-ros-bridge", bridge, work / "bridge.log")
            figures.update(ros_part(build, url, types, a.window_s, watch))
            figures.update(octave_part(build, url, a.window_s, watch))
        except (RuntimeError, subprocess.TimeoutExpired) as e:
            log(f"ERROR: {e}")
        finally:
            watch.stop = True
            procs.stop_all()
        figures.update(serial_leg(build, work))
    serial = figures.get("cmd_to_serial_us_p50")
    figures["ros_cmd_to_serial_us_p50"] = add(figures.get("ros_cmd_to_lcm_us_p50"), serial)
    figures["octave_cmd_to_serial_us_p50"] = add(figures.get("octave_cmd_to_lcm_us_p50"), serial)
    print_figures(judge(figures, GOALS, UNSEEDED))
    return 0
