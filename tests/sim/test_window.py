"""autodrive-sim --view driven as a person would (issue 36): the real program in its own Xvfb,
keys and a mouse click injected with xdotool, the screen grabbed with ffmpeg (x11grab), the
car's ground truth read on real LCM UDP multicast. Checks: the camera keys change the picture,
night darkens it by a measured amount, C draws the camera thumbnails, R puts the car back at its start, and the Menu Panel's
Record button writes an LCM log and a playable MP4 whose frame count matches its duration in
sim time. The screenshots go to $AUTODRIVE_SCREENSHOT_DIR when set (the docs' pictures).
Judged by sim time, frames and pixels; the waits are guards that fail with what was seen."""

from __future__ import annotations

import csv
import subprocess
from collections.abc import Iterator
from pathlib import Path

import cv2
import numpy as np
import pytest

from autodrive.core.channels import channel, vehicle_name
from window_rig import GUARD_S, NEEDS_X_TOOLS, WIN_H, WIN_W, WindowRig

PANEL_W = 260  # [px] the Menu Panel's width (mjui theme 0): the scene is right of it
RECORD_BUTTON = (68, 581)  # [px] the Record button (tests/sim_sensors checks the layout)
FPS = 30.0

pytestmark = NEEDS_X_TOOLS


class Window(WindowRig):
    """The program on its display, with its ground truth and its stdout lines."""

    def __init__(self, build: Path, tmp: Path, url: str) -> None:
        super().__init__(build, tmp, url, display_offset=0)
        self.lc.subscribe(channel("GROUND_TRUTH", vehicle_name(1)), self._on_truth)
        self.hud_log = tmp / "hud.log"  # a line per frame drawn (the drawing has a thread)
        self.start_sim(
            [str(build / "bin" / "autodrive-sim"), "--view", "--view-size", f"{WIN_W}x{WIN_H}", "--no-pty", "--no-lidar",
             "--rtf", "1", "--duration", "3600", "--run-dir", str(tmp), "--lcm-url", url,
             "--script", "constant:throttle=0.35,steering=0", "--hud-log", str(self.hud_log),
             "--quiet"],
        )  # fmt: skip
        self.wid = self.until(self.window_id, "the window to appear")

    def _on_truth(self, _c: str, data: bytes) -> None:
        m = self.types.ground_truth_t.decode(data)
        self.truth.append((m.utime * 1e-6, m.position_m[0], m.position_m[1]))  # (t [s], x, y [m])

    def frames(self) -> int:
        return len(self.hud_log.read_text().splitlines()) if self.hud_log.exists() else 0

    def drawn_since(self) -> None:
        """Waits for the event to be polled (at ~30 Hz of wall time, so within 0.15 s of sim
        time at rtf 1) and then for two frames more: the one that took it, and one that shows
        it."""
        self.run_sim(0.15)
        n = self.frames()
        self.until(lambda: "ok" if self.frames() >= n + 2 else None, "two frames drawn")

    def key(self, name: str) -> None:
        self.xdotool("key", "--window", self.wid, name)
        self.drawn_since()

    def click(self, x: int, y: int) -> None:
        self.xdotool("mousemove", "--window", self.wid, str(x), str(y), "click", "1")
        self.drawn_since()

    def shot_image(self, name: str) -> np.ndarray:
        path = self.shot(name)
        img = cv2.imread(str(path))
        assert img is not None, path
        return img

    def close(self) -> int:
        return self.stop_sim_and_display()


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
    bird = w.shot_image("window-bird")
    w.key("3")
    god = w.shot_image("window-god")
    assert np.abs(scene(bird) - scene(god)).mean() > 10, "the camera did not change"
    w.key("n")
    night = w.shot_image("window-god-night")
    ratio = scene(night).mean() / scene(god).mean()
    print(f"night / day brightness of the scene: {ratio:.2f}")
    assert ratio < 0.6, f"night darkened the scene to {ratio:.2f} of the day only"
    w.key("n")

    # C: the ego car's front and rear cameras as thumbnails at the bottom left of the scene
    thumbs = (slice(WIN_H - 150, WIN_H - 40), slice(PANEL_W + 10, PANEL_W + 300))
    plain = w.shot_image("window-god-plain")[thumbs].astype(np.float64)
    w.key("c")
    cams = w.shot_image("window-cameras")[thumbs].astype(np.float64)
    change = np.abs(cams - plain).mean()
    print(f"camera thumbnails changed their corner by {change:.1f} grey levels")
    assert change > 10, f"C drew no camera thumbnails (the corner changed by {change:.1f})"
    w.key("c")

    # R puts the car back: it has driven off its start, then is back within 5 cm
    t0, x0, y0 = w.truth[0]
    w.until(lambda: "ok" if abs(w.truth[-1][1] - x0) + abs(w.truth[-1][2] - y0) > 0.15 else None,
             "the car to drive 0.15 m")  # fmt: skip
    t_key = w.sim_time()
    w.key("r")
    back = [s for s in w.truth if s[0] > t_key and abs(s[1] - x0) + abs(s[2] - y0) < 0.05]
    assert back, f"after R the car never came back to ({x0:.2f}, {y0:.2f})"

    # the Record button: a log and a video in step on sim time
    w.click(*RECORD_BUTTON)
    started = w.until(lambda: next((s for s in w.lines if s.startswith("recording ")), None),
                       "the recording to start")  # fmt: skip
    w.shot_image("window-recording")
    w.run_sim(1.0)
    w.click(*RECORD_BUTTON)
    w.until(lambda: next((s for s in w.lines if s.startswith("recording stopped")), None),
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
    assert w.sim is not None and w.sim.wait(timeout=GUARD_S) == 0
