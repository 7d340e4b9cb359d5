"""autodrive-sim --view driven as a person would (issue 36): the real program in its own Xvfb,
keys and a mouse click injected with xdotool, the screen grabbed with ffmpeg (x11grab), the
car's ground truth read on real LCM UDP multicast. Checks: the camera keys change the picture,
night darkens it by a measured amount, R puts the car back at its start, and the Menu Panel's
Record button writes an LCM log and a playable MP4 whose frame count matches its duration in
sim time. The screenshots go to $AUTODRIVE_SCREENSHOT_DIR when set (the docs' pictures).
Judged by sim time, frames and pixels; the waits are guards that fail with what was seen."""

from __future__ import annotations

import csv
import os
import select
import shutil
import signal
import subprocess
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import cv2
import numpy as np
import pytest

from autodrive.core import lcmtypes
from autodrive.core.channels import channel, vehicle_name

WIN_W, WIN_H = 800, 600  # [px] --view-size: small, for llvmpipe on a busy CPU
PANEL_W = 260  # [px] the Menu Panel's width (mjui theme 0): the scene is right of it
RECORD_BUTTON = (68, 581)  # [px] the Record button (tests/sim_sensors checks the layout)
GUARD_S = 240.0  # [s] wall: a guard against a hung run, never a pass criterion
FPS = 30.0

pytestmark = pytest.mark.skipif(
    not (shutil.which("Xvfb") and shutil.which("xdotool") and shutil.which("ffmpeg")),
    reason="needs Xvfb, xdotool and ffmpeg (tools/debian-packages.txt)",
)


class Window:
    """The program on its display, with its ground truth and its stdout lines."""

    def __init__(self, build: Path, tmp: Path, url: str) -> None:
        self.display = f":{300 + os.getpid() % 600}"
        self.xvfb = subprocess.Popen(
            ["Xvfb", self.display, "-screen", "0", f"{WIN_W}x{WIN_H}x24", "-nolisten", "tcp"],
            stderr=subprocess.DEVNULL,
        )
        self.env = dict(os.environ, DISPLAY=self.display)
        self.types = lcmtypes.load(build)
        self.lc = lcmtypes.bus(url)
        self.truth: list[tuple[float, float, float]] = []  # (sim time [s], x, y [m])
        self.lc.subscribe(channel("GROUND_TRUTH", vehicle_name(1)), self._on_truth)
        self.tmp = tmp
        self.sim = subprocess.Popen(
            [str(build / "bin" / "autodrive-sim"), "--view", "--view-size", f"{WIN_W}x{WIN_H}", "--no-pty", "--no-lidar",
             "--rtf", "1", "--duration", "3600", "--run-dir", str(tmp), "--lcm-url", url,
             "--script", "constant:throttle=0.35,steering=0", "--quiet"],
            cwd=tmp, env=self.env, stdout=subprocess.PIPE, text=True,
        )  # fmt: skip
        self.lines: list[str] = []
        self.wid = self._until(self._window_id, "the window to appear")

    def _on_truth(self, _c: str, data: bytes) -> None:
        m = self.types.ground_truth_t.decode(data)
        self.truth.append((m.utime * 1e-6, m.position_m[0], m.position_m[1]))

    def _window_id(self) -> str | None:
        r = subprocess.run(["xdotool", "search", "--name", "AutoDRIVE Nigel sim"],
                           env=self.env, capture_output=True, text=True)  # fmt: skip
        return r.stdout.split()[0] if r.returncode == 0 and r.stdout.split() else None

    def pump(self) -> None:
        """Reads the LCM messages and the program's stdout lines that arrived."""
        while select.select([self.lc.fileno()], [], [], 0.02)[0]:
            self.lc.handle()
        assert self.sim.stdout is not None
        while select.select([self.sim.stdout], [], [], 0)[0]:
            line = self.sim.stdout.readline()
            if not line:
                break
            self.lines.append(line.strip())

    def _until(self, what: Callable[[], str | None], saying: str) -> str:
        t0 = time.monotonic()
        while time.monotonic() - t0 < GUARD_S:
            self.pump()
            got = what()
            if got:
                return got
            assert self.sim.poll() is None, f"the simulator exited ({self.sim.returncode})"
        raise AssertionError(f"waited for {saying}; stdout: {self.lines[-5:]}")

    def sim_time(self) -> float:
        self.pump()
        return self.truth[-1][0] if self.truth else 0.0

    def run_sim(self, seconds: float) -> float:
        """Waits until the sim time has advanced by seconds; returns it."""
        t_end = self.sim_time() + seconds
        self._until(lambda: "ok" if self.sim_time() >= t_end else None, f"sim time {t_end:.1f} s")
        return self.sim_time()

    def key(self, name: str) -> None:
        subprocess.run(["xdotool", "key", "--window", self.wid, name], env=self.env, check=True)
        self.run_sim(0.15)  # a few frames drawn since

    def click(self, x: int, y: int) -> None:
        subprocess.run(["xdotool", "mousemove", "--window", self.wid, str(x), str(y), "click", "1"],
                       env=self.env, check=True)  # fmt: skip
        self.run_sim(0.15)

    def shot(self, name: str) -> np.ndarray:
        path = self.tmp / f"{name}.png"
        subprocess.run(["ffmpeg", "-v", "error", "-y", "-f", "x11grab", "-video_size",
                        f"{WIN_W}x{WIN_H}", "-i", f"{self.display}+0,0", "-frames:v", "1",
                        str(path)], env=self.env, check=True)  # fmt: skip
        out = os.environ.get("AUTODRIVE_SCREENSHOT_DIR")
        if out:
            shutil.copy(path, Path(out) / f"{name}.png")
        img = cv2.imread(str(path))
        assert img is not None, path
        return img

    def close(self) -> int:
        if self.sim.poll() is None:
            self.sim.send_signal(signal.SIGINT)
            try:
                self.sim.wait(timeout=60)
            except subprocess.TimeoutExpired:
                self.sim.kill()
                self.sim.wait()
        self.xvfb.terminate()
        self.xvfb.wait()
        return int(self.sim.returncode)


@pytest.fixture
def window(build_dir: Path, tmp_path: Path, lcm_url: str) -> Iterator[Window]:
    w = Window(build_dir, tmp_path, lcm_url)
    try:
        yield w
    finally:
        w.close()


def scene(img: np.ndarray) -> np.ndarray:
    """The scene right of the Menu Panel, below the HUD's top rows, above the status line."""
    return img[270 : WIN_H - 40, PANEL_W + 10 : WIN_W].astype(np.float64)


def test_window_as_a_person_uses_it(window: Window) -> None:
    w = window
    w.run_sim(0.3)
    w.key("2")
    bird = w.shot("window-bird")
    w.key("3")
    god = w.shot("window-god")
    assert np.abs(scene(bird) - scene(god)).mean() > 10, "the camera did not change"
    w.key("n")
    night = w.shot("window-god-night")
    ratio = scene(night).mean() / scene(god).mean()
    print(f"night / day brightness of the scene: {ratio:.2f}")
    assert ratio < 0.6, f"night darkened the scene to {ratio:.2f} of the day only"
    w.key("n")

    # R puts the car back: it has driven off its start, then is back within 5 cm
    t0, x0, y0 = w.truth[0]
    w._until(lambda: "ok" if abs(w.truth[-1][1] - x0) + abs(w.truth[-1][2] - y0) > 0.15 else None,
             "the car to drive 0.15 m")  # fmt: skip
    t_key = w.sim_time()
    w.key("r")
    back = [s for s in w.truth if s[0] > t_key and abs(s[1] - x0) + abs(s[2] - y0) < 0.05]
    assert back, f"after R the car never came back to ({x0:.2f}, {y0:.2f})"

    # the Record button: a log and a video in step on sim time
    w.click(*RECORD_BUTTON)
    started = w._until(lambda: next((s for s in w.lines if s.startswith("recording ")), None),
                       "the recording to start")  # fmt: skip
    w.shot("window-recording")
    w.run_sim(1.0)
    w.click(*RECORD_BUTTON)
    w._until(lambda: next((s for s in w.lines if s.startswith("recording stopped")), None),
             "the recording to stop")  # fmt: skip
    folder = w.tmp / started.split(" into ")[-1]
    rows = list(csv.DictReader((folder / "view_frames.csv").open()))
    sim_us = [int(r["sim_time_us"]) for r in rows]
    cap = cv2.VideoCapture(str(folder / "view.mp4"))
    frames = 0
    while cap.read()[0]:
        frames += 1
    print(f"recorded {frames} frames over {(sim_us[-1] - sim_us[0]) * 1e-6:.2f} s of sim time")
    assert frames == len(rows) >= 1.0 * FPS
    assert frames / FPS == pytest.approx((sim_us[-1] - sim_us[0]) * 1e-6, abs=2 / FPS)
    assert (folder / "run.lcmlog").read_bytes().count(b"NIGEL1_GROUND_TRUTH") > 20
    subprocess.run(["xdotool", "key", "--window", w.wid, "Escape"], env=w.env, check=True)
    assert w.sim.wait(timeout=GUARD_S) == 0
