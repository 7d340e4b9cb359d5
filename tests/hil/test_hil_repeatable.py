"""HIL repeatability: autodrive-sim --lockstep-frames (seed 7) with the unchanged runtime on its
Nano pty (bridge.sync_to_sim_clock: one frame per SIM_CLOCK tick) and an engaged command
scheduled for 0.3 s of sim time on real UDP LCM: two runs write the same ground-truth bytes, and
the car drove."""

from __future__ import annotations

import pathlib
import subprocess
import os
import tempfile
import threading
import time

import yaml

from autodrive.core import command_auth
from autodrive.core import lcmtypes
from autodrive.core.channels import channel
from autodrive.core.settings import RUNTIME_HIL_CONFIG


def test_lockstep_run_repeats(
    root: pathlib.Path, build_dir: pathlib.Path, lcm_port: int, lcm_url: str
) -> None:
    build, port = build_dir, lcm_port
    url = lcm_url
    SIM_S, SEED, VEHICLE, ENGAGE_AT_US = 4.0, 7, "NIGEL1", 300000
    types = lcmtypes.load(build)
    # A test key for the car, seen by the runtime's bridge and by the driver below.
    key_dir = tempfile.TemporaryDirectory(prefix="hil-repeat-keys-")
    os.environ["AUTODRIVE_KEY_DIR"] = key_dir.name
    command_auth.create_key(command_auth.default_key_path(VEHICLE))

    def drive(stop: threading.Event) -> None:
        """One engaged command, stamped ENGAGE_AT_US of sim time, repeated at 50 Hz of wall time:
        the bridge (sync_to_sim_clock) sends disengaged frames until that tick, then this one, so
        the firmware arms (disengaged, then engaged) at the same step in every run."""
        bus = lcmtypes.bus(url)
        signer = command_auth.signer_for(VEHICLE, "hil-repeat")
        seq = 0
        while not stop.is_set():
            c = types.vehicle_command_t()
            c.utime, c.seq, c.throttle, c.steering, c.engaged = (
                ENGAGE_AT_US,
                seq,
                0.6,
                0.4,
                True,
            )
            bus.publish(channel("COMMAND", VEHICLE), signer.sign(c).encode())
            seq += 1
            time.sleep(0.02)

    def run(tmp: pathlib.Path, name: str) -> bytes:
        run_dir, truth = tmp / f"{name}-run", tmp / f"{name}.truth"
        cfg = yaml.safe_load(RUNTIME_HIL_CONFIG.read_text())
        cfg.update(lcm_url=url, clock="sim")
        cfg["vehicle"] = {"name": VEHICLE}
        cfg["bridge"].update(device=str(run_dir / "nigel1-nano"), sync_to_sim_clock=True)
        # a loaded machine must not let the constant command go stale between two wall ticks
        cfg["bridge"]["command_timeout_ms"] = 500  # the bound the config reader allows
        for optional in ("lidar", "cameras", "estimator"):
            cfg.pop(optional, None)
        cfg_path = tmp / f"{name}.yaml"
        cfg_path.write_text(yaml.safe_dump(cfg))
        stop = threading.Event()
        driver = threading.Thread(target=drive, args=(stop,), daemon=True)
        driver.start()
        # The runtime first: its bridge holds the driver's command before the sim's pty exists, so
        # the first frame after the handshake is the same engaged command in every run.
        runtime = subprocess.Popen(
            [str(build / "bin" / "autodrive-runtime"), "--config", str(cfg_path)],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        time.sleep(1.0)
        sim = subprocess.Popen(
            [str(build / "bin" / "autodrive-sim"), "--lockstep-frames", "--seed", str(SEED)]
            + ["--duration", str(SIM_S), "--truth-log", str(truth), "--run-dir", str(run_dir)]
            + ["--lcm-url", url, "--no-lidar-lcm", "--quiet"],
            stdout=subprocess.DEVNULL,
        )
        try:
            assert sim.wait(timeout=300) == 0, f"{name}: autodrive-sim failed"
        finally:
            for p in (runtime, sim):
                if p.poll() is None:
                    p.terminate()
                    p.wait(timeout=20)
            stop.set()
            driver.join()
        return truth.read_bytes()

    with tempfile.TemporaryDirectory(prefix="hil-repeat-") as tmp:
        a = run(pathlib.Path(tmp), "a")
        b = run(pathlib.Path(tmp), "b")

    def positions(log: bytes) -> list[tuple[float, float]]:
        """Each ground-truth record's (x, y) [m]: a 4-byte length, then the LCM message."""
        out, i = [], 0
        while i + 4 <= len(log):
            n = int.from_bytes(log[i : i + 4], "big")
            m = types.ground_truth_t.decode(log[i + 4 : i + 4 + n])
            out.append((m.position_m[0], m.position_m[1]))
            i += 4 + n
        return out

    track = positions(a)
    assert len(track) >= 0.9 * 100 * SIM_S, f"only {len(track)} ground-truth records"
    moved_m = ((track[-1][0] - track[0][0]) ** 2 + (track[-1][1] - track[0][1]) ** 2) ** 0.5
    assert moved_m > 0.2, f"the car moved {moved_m:.3f} m: the runtime's commands did not reach it"
    if a != b:
        first = next(i for i in range(min(len(a), len(b))) if a[i] != b[i])
        raise AssertionError(f"two runs differ from byte {first} of {len(a)} / {len(b)}")
    print(
        f"two HIL runs of {SIM_S} s sim, the car {moved_m:.2f} m from its start: the same {len(a)} bytes of ground truth"
    )
