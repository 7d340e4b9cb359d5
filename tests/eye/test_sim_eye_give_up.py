"""eye.Sim.GiveUpFailsTheReport: a planted failure of the Eye lockstep's hang guard.
`autodrive-sim --lockstep --eye --eye-sync --eye-sync-wait-s 0.5` (a scripted car under Parking
School's overhead camera, 1 s of sim time) with a test double for the Eye that says it is ready
(EYE_FRAME_DONE, utime -1) until the first frame comes, then never answers one: an Eye that
hangs on its first frame. The sim must give it up (a stderr line with the give-up mark, counted in --bench's
eye_sync_give_ups and the exit line), and the missions' verdict on that log
(autodrive.hil.pose_source, as smart city, intersection and parking use it) must fail the report
naming the count and --eye-sync-wait-s. The outcome does not depend on the host's load: the
double never answers, so the guard fires however fast the machine is; only how long the run
takes in wall time does (about 0.5 s per give-up)."""

from __future__ import annotations

import json
import os
import subprocess
import threading
from pathlib import Path

from autodrive.bench.eye_sim import CAR_SCRIPT
from autodrive.core import lcmtypes
from autodrive.core.channels import channel
from autodrive.hil import pose_source

PORT = os.environ.get("EYE_GIVE_UP_PORT", "7808")
URL = f"udpm://239.255.76.67:{PORT}?ttl=0"
RECV_BUF_BYTES = 4194304  # the double's socket gets the JPEG frames
LATENCY_US = 15000
WAIT_S = 0.5  # the sim's give-up time [s wall]: short, the double never answers anyway


class SilentEye:
    """Test double: an Eye that is ready every 0.1 s of wall time until the first frame, then
    silent (it never says a frame is done)."""

    def __init__(self, build: Path) -> None:
        self.types = lcmtypes.load(build)
        self.lc = lcmtypes.bus(f"{URL}&recv_buf_size={RECV_BUF_BYTES}")
        self.frame_seen = threading.Event()
        self.stop = threading.Event()
        self.lc.subscribe(channel("EYE_IMAGE"), lambda _c, _d: self.frame_seen.set())
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _run(self) -> None:
        ready = self.types.eye_frame_done_t()
        ready.utime, ready.latency_us, ready.poses = -1, LATENCY_US, 0
        while not self.stop.is_set():
            if not self.frame_seen.is_set():
                self.lc.publish(channel("EYE_FRAME_DONE"), ready.encode())
            self.lc.handle_timeout(100)

    def close(self) -> None:
        self.stop.set()
        self.thread.join()


def test_give_up_fails_the_report(build_dir: Path, tmp_path: Path) -> None:
    eye = SilentEye(build_dir)
    try:
        sim = subprocess.run(
            [str(build_dir / "bin" / "autodrive-sim"), "--lockstep", "--no-pty", "--no-lidar"]
            + ["--eye", "--eye-sync", "--eye-sync-wait-s", str(WAIT_S), "--camera-fps", "5"]
            + ["--script", CAR_SCRIPT, "--duration", "1", "--bench", "--lcm-url", URL]
            + ["--run-dir", str(tmp_path / "run")],
            capture_output=True,
            text=True,
            timeout=300,  # a hang guard only
        )
    finally:
        eye.close()
    print(sim.stderr[-2000:])
    assert sim.returncode == 0, f"autodrive-sim exited {sim.returncode}"
    bench = json.loads(sim.stdout.strip().splitlines()[-1])
    log = tmp_path / "sim.log"
    log.write_text(sim.stderr)
    give_ups = pose_source.eye_sync_give_ups(log, LATENCY_US / 1000)
    assert give_ups is not None and give_ups >= 1, "the sim did not give the silent Eye up"
    assert bench["eye_sync_give_ups"] == give_ups, (bench, give_ups)
    assert f"gave it up {give_ups} time(s)" in sim.stderr
    rep = pose_source.report("cameras", "silent double", [], [], LATENCY_US / 1000, give_ups)
    rep["ok"] = True  # every other goal met
    pose_source.eye_sync_verdict(rep)
    assert rep["ok"] is False
    assert rep["eye_sync_give_ups"] == give_ups
    assert rep["error"].startswith(f"the Eye fell behind the sim {give_ups} times"), rep["error"]
    assert "--eye-sync-wait-s" in rep["error"]
    print(f"PASS: {give_ups} give-up(s) counted, the report fails: {rep['error']}")
