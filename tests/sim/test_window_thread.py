"""The window draws on a thread of its own (issue 36): with --view the stepping goes on while a
frame is drawn, and the run is the run without the window. The real program, free --lockstep,
on its own Xvfb (llvmpipe), ground truth written by the sim itself (--truth-log). Judged by
bytes, steps and frames, never by wall time."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

from window_rig import NEEDS_X_TOOLS, WindowRig

SIM_S = 60.0  # [s] sim time: ~1 s of wall time in free lockstep (release), a few frames
SCRIPT = "constant:throttle=0.5,steering=0.3"

pytestmark = NEEDS_X_TOOLS


def _run(rig: WindowRig, build: Path, url: str, name: str, *extra: str) -> tuple[bytes, dict]:
    truth = rig.tmp / f"{name}.truth"
    argv = [str(build / "bin" / "autodrive-sim"), "--lockstep", "--no-pty", "--quiet", "--bench",
            "--duration", str(SIM_S), "--script", SCRIPT, "--run-dir", str(rig.tmp),
            "--lcm-url", url, "--truth-log", str(truth), *extra]  # fmt: skip
    out = subprocess.run(argv, env=rig.env, check=True, capture_output=True, text=True).stdout
    return truth.read_bytes(), json.loads(out.strip().splitlines()[-1])


def test_stepping_goes_on_while_the_window_draws(
    build_dir: Path, tmp_path: Path, lcm_url: str
) -> None:
    rig = WindowRig(build_dir, tmp_path, lcm_url, display_offset=2)
    try:
        headless, _ = _run(rig, build_dir, lcm_url, "headless")
        hud = tmp_path / "hud.log"
        windowed, bench = _run(rig, build_dir, lcm_url, "window", "--view", "--hud-log", str(hud))
    finally:
        rig.close_display()
    print({k: v for k, v in bench.items() if k.startswith("viewer")})
    # the window only reads the state: the same steps, the same ground truth, byte for byte
    assert len(headless) > 0 and windowed == headless, "the window changed the run"
    assert bench["steps"] == round(SIM_S * 1000)
    frames_us = [int(line.split("\t")[0]) for line in hud.read_text().splitlines()]
    # >= 1: under ASan the first frame (the shaders, the panel's buffer) can outlast the run
    assert bench["viewer_frames"] == len(frames_us) >= 1, bench
    assert frames_us == sorted(frames_us), "frames drawn out of sim-time order"
    # the stepping did not wait for GL: it stepped while frames were being drawn
    assert bench["viewer_steps_while_drawing"] > 0, bench
    assert bench["viewer_snapshots"] >= bench["viewer_frames"]
