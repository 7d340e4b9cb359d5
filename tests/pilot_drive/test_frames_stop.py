"""Frames that stop arriving stop the car, on the real chain: autodrive-sim (Driving School,
--lockstep-client, --allow-teleport), the unchanged autodrive-runtime (bridge, estimator) on its
Nano pty, and autodrive-pilot with a random fixture model, over real LCM (UDP multicast on
loopback, port from argv). The test publishes camera-sized JPEG frames on NIGEL1_CAM_FRONT: the
pilot engages and the car moves. Then the frames stop: the pilot logs that it stops the car,
its commands are disengaged, and the car (ground truth) comes to a standstill. Frames again: it
drives again. Last, SIM_TELEPORT puts the car on a given pose (and one off the map is refused).
Every component and the test's frames run on the simulator's clock (SIM_CLOCK): the frames are
paced and the waits measured in sim time, so a loaded machine only slows the run."""
import math
import pathlib
import select
import subprocess
import tempfile
import time

import yaml

import fixture
from autodrive.core import channels
from autodrive.core import lcmtypes
from autodrive import maps
from autodrive.core.settings import RUNTIME_HIL_CONFIG

HANG_BACKSTOP_S = 120.0  # wall time [s]: ends a hung run only, never a pass/fail figure


def test_frames_stop_stop_the_car(
    root: pathlib.Path, build_dir: pathlib.Path, lcm_port: int, lcm_url: str
) -> None:
    build, port = build_dir, lcm_port
    url = lcm_url
    types = lcmtypes.load(build)
    veh = channels.vehicle_name(1)
    lc = lcmtypes.bus(url)
    truth: dict[str, float] = {}
    commands: list[tuple[int, bool, str]] = []  # (sim time received [us], engaged, source)
    clock = {"us": -1}  # the simulator's time [us] (SIM_CLOCK); -1 before its first tick

    def on_truth(_c: str, d: bytes) -> None:
        m = types.ground_truth_t.decode(d)
        truth.update(
            x=m.position_m[0], y=m.position_m[1], yaw=m.yaw_rad, v=m.linear_velocity_m_s[0]
        )

    def on_command(_c: str, d: bytes) -> None:
        m = types.vehicle_command_t.decode(d)
        commands.append((clock["us"], bool(m.engaged), m.source))

    def on_clock(_c: str, d: bytes) -> None:
        clock["us"] = types.sim_clock_t.decode(d).utime

    lc.subscribe(channels.channel("SIM_CLOCK"), on_clock)
    lc.subscribe(channels.channel("GROUND_TRUTH", veh), on_truth)
    lc.subscribe(channels.channel("COMMAND", veh), on_command)

    def pump(sim_s: float, frames: list[bytes] | None = None, fps: float = 30.0) -> None:
        """Handles the bus for sim_s of sim time; publishes frames (cycled) at fps of sim time
        meanwhile when given. The wall backstop only ends a hung run."""
        backstop = time.monotonic() + HANG_BACKSTOP_S
        while clock["us"] < 0:
            assert time.monotonic() < backstop, "no SIM_CLOCK"
            if select.select([lc.fileno()], [], [], 0.005)[0]:
                lc.handle()
        end_us, next_frame_us, i = clock["us"] + int(sim_s * 1e6), clock["us"], 0
        while clock["us"] < end_us:
            assert time.monotonic() < backstop, f"sim time stuck at {clock['us']} us"
            if frames is not None and clock["us"] >= next_frame_us:
                img = types.compressed_image_t()
                img.utime, img.frame_id, img.format = clock["us"], "camera_front", "jpeg"
                img.width_px, img.height_px = fixture.SOURCE_W, fixture.SOURCE_H
                img.data = frames[i % len(frames)]
                img.size_bytes = len(img.data)
                lc.publish(channels.channel("CAM_FRONT", veh), img.encode())
                i += 1
                next_frame_us += int(1e6 / fps)
            if select.select([lc.fileno()], [], [], 0.005)[0]:
                lc.handle()

    def teleport(x: float, y: float, yaw: float) -> None:
        m = types.pose2d_t()
        m.vehicle, m.frame_id, m.x_m, m.y_m, m.yaw_rad = veh, "map", x, y, yaw
        m.covariance = [0.0] * 9
        lc.publish(channels.channel("SIM_TELEPORT"), m.encode())

    with tempfile.TemporaryDirectory(prefix="pilot-stop-") as tmp:
        out = pathlib.Path(tmp)
        model, _ = fixture.export(out)
        jpegs = [p.read_bytes() for p in fixture.frames(out, 10)]
        route = maps.load("driving_school").route("loop_ccw")
        start = route.pose_at(0.6)
        run_dir = out / "run"
        rcfg = yaml.safe_load(RUNTIME_HIL_CONFIG.read_text())
        rcfg.update(lcm_url=url, clock="sim")
        rcfg["bridge"]["device"] = str(run_dir / "nigel1-nano")
        (out / "runtime.yaml").write_text(yaml.safe_dump(rcfg))
        pcfg = yaml.safe_load((root / "runtime/jetson/config/pilot_hil.yaml").read_text())
        # the test's frames are paced on the sim clock: so is the pilot's timeout [ms of sim time]
        pcfg.update(lcm_url=url, model=str(model), frame_timeout_ms=300, clock="sim")
        (out / "pilot.yaml").write_text(yaml.safe_dump(pcfg))
        bin_ = build / "bin"
        sim_log, pilot_log = open(out / "sim.log", "w"), open(out / "pilot.log", "w")
        procs = [
            subprocess.Popen(
                [bin_ / "autodrive-sim", "--map", "driving_school", "--run-dir", run_dir, "--lcm-url",
                 url, "--no-lidar", "--quiet", "--lockstep-client", "--allow-teleport", "--duration",
                 "300", "--start", f"{start.x_m},{start.y_m},{math.degrees(start.yaw_rad)}"],
                stdout=sim_log, stderr=subprocess.STDOUT)  # fmt: skip
        ]
        try:
            backstop = time.monotonic() + HANG_BACKSTOP_S
            while not (run_dir / "nigel1-nano").exists():
                assert (
                    time.monotonic() < backstop and procs[0].poll() is None
                ), "the sim did not start"
                time.sleep(0.05)
            procs.append(subprocess.Popen(
                [bin_ / "autodrive-runtime", "--config", out / "runtime.yaml", "--only",
                 "bridge,estimator"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))  # fmt: skip
            procs.append(subprocess.Popen(
                [bin_ / "autodrive-pilot", "--config", out / "pilot.yaml"], stdout=pilot_log,
                stderr=subprocess.STDOUT))  # fmt: skip
            pump(3.0)
            assert truth, "no ground truth"
            assert not commands, "the pilot commanded before any frame"
            # frames: the pilot drives
            pump(5.0, jpegs)
            driving = [c for c in commands if c[2] == "pilot"]
            assert driving and all(e for _, e, _ in driving[-20:]), "the pilot did not engage"
            assert truth["v"] > 0.05, f"the car does not move ({truth['v']:.3f} m/s)"
            print(f"driving: {len(driving)} commands, {truth['v']:.3f} m/s")
            # no frames: within the timeout, the pilot stops the car
            t_stop = clock["us"]
            pump(3.0)
            after = [c for c in commands if c[0] > t_stop + 500_000]
            assert after and not any(
                e for _, e, _ in after
            ), "commands still engaged without frames"
            first_off = next(c[0] for c in commands if c[0] > t_stop and not c[1])
            assert abs(truth["v"]) < 0.01, f"the car still moves ({truth['v']:.3f} m/s)"
            log = (out / "pilot.log").read_text()
            assert "STOPPING the car" in log and "CAM_FRONT" in log, log
            print(
                f"frames stopped: disengaged after {(first_off - t_stop) * 1e-6:.2f} s of sim time, car at {truth['v']:.4f} m/s"
            )
            # frames again: it drives again
            pump(3.0, jpegs)
            assert commands[-1][1], "the pilot did not drive again"
            assert "frames again" in (out / "pilot.log").read_text()
            # SIM_TELEPORT: back to the start, standing; off the floor: refused and logged
            pump(1.0)
            teleport(start.x_m, start.y_m, start.yaw_rad)
            pump(1.0)
            assert math.hypot(truth["x"] - start.x_m, truth["y"] - start.y_m) < 0.02, truth
            teleport(40.0, 0.0, 0.0)
            pump(0.5)
            sim_log.flush()
            assert "SIM_TELEPORT refused" in (out / "sim.log").read_text()
            print("teleport ok")
        finally:
            for p in reversed(procs):
                p.send_signal(2)
                try:
                    p.wait(timeout=10)
                except subprocess.TimeoutExpired:
                    p.kill()
    print("OK")
