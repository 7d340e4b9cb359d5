"""The View section's Cam scale radio sets the render scale of the cars' sensor cameras live
(issue 36): autodrive-sim --view --front-camera in its own Xvfb, real LCM, the car standing
still (no driver). xdotool clicks Cam scale 0.25, then 1. Checks, on the published
NIGEL1_CAM_FRONT frames: each keeps its size; the frames stamped after the change (sim time,
the program's own line) differ from the full-scale ones by more than two full-scale frames
differ from each other (the measure of sim.sensors_camera's RenderScaleKeepsTheFrameSize...:
the mean |full - scaled| in grey levels), and carry less detail (mean |horizontal gradient|);
back at 1 they are the full frames again. The window's picture with its View section
(window-view-panel.png) goes to $AUTODRIVE_SCREENSHOT_DIR when set (the docs'). Judged on sim
time and pixels; the waits are guards that fail with what was seen."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import cv2
import numpy as np
import pytest

from autodrive.core.channels import channel, vehicle_name
from window_rig import GUARD_S, NEEDS_X_TOOLS, WIN_H, WIN_W, WindowRig

# [px] the View section's Cam scale radio (tests/sim_sensors checks the layout)
CAM_SCALE_QUARTER = (221, 453)
CAM_SCALE_FULL = (134, 453)

pytestmark = NEEDS_X_TOOLS


class Window(WindowRig):
    """The program on its display, its ground truth, its front camera's frames."""

    def __init__(self, build: Path, tmp: Path, url: str) -> None:
        super().__init__(build, tmp, url, display_offset=13)
        veh = vehicle_name(1)
        self.frames: list[tuple[float, np.ndarray]] = []  # (sim time [s], grey image)
        self.sizes: set[tuple[int, int]] = set()  # (width, height) [px] as published
        self.lc.subscribe(channel("GROUND_TRUTH", veh), self._on_truth)
        self.lc.subscribe(channel("CAM_FRONT", veh), self._on_frame)
        self.start_sim(
            [str(build / "bin" / "autodrive-sim"), "--view", "--view-size", f"{WIN_W}x{WIN_H}",
             "--no-pty", "--no-lidar", "--front-camera", "--rtf", "1", "--duration", "3600",
             "--run-dir", str(tmp), "--lcm-url", url, "--quiet"],
        )  # fmt: skip
        self.wid = self.until(self.window_id, "the window to appear")

    def _on_truth(self, _c: str, data: bytes) -> None:
        self.truth.append((self.types.ground_truth_t.decode(data).utime * 1e-6,))

    def _on_frame(self, _c: str, data: bytes) -> None:
        m = self.types.compressed_image_t.decode(data)
        img = cv2.imdecode(np.frombuffer(m.data, np.uint8), cv2.IMREAD_GRAYSCALE)
        assert img is not None and img.shape == (m.height_px, m.width_px), (m.format, m.width_px)
        self.sizes.add((m.width_px, m.height_px))
        self.frames.append((m.utime * 1e-6, img.astype(np.float64)))

    def click(self, x: int, y: int) -> None:
        self.xdotool("mousemove", "--window", self.wid, str(x), str(y), "click", "1")

    def scale_set(self, scale: str) -> float:
        """Waits for the program's line that the cameras render at scale; its sim time [s]."""
        line = self.until(lambda: next((s for s in self.lines
                                        if s.startswith(f"camera scale {scale} from t = ")), None),
                          f"the cameras to take scale {scale}")  # fmt: skip
        return float(line.split(" from t = ")[1].split()[0])

    def frame_after(self, t_s: float) -> np.ndarray:
        """The first frame stamped after sim time t_s."""
        self.until(lambda: "ok" if any(t > t_s for t, _ in self.frames) else None,
                   f"a frame after t = {t_s:.3f} s")  # fmt: skip
        return next(f for t, f in self.frames if t > t_s)


@pytest.fixture
def window(build_dir: Path, tmp_path: Path, lcm_url: str) -> Iterator[Window]:
    w = Window(build_dir, tmp_path, lcm_url)
    try:
        yield w
    finally:
        w.stop_sim_and_display()


def differ(a: np.ndarray, b: np.ndarray) -> float:
    """Mean |a - b| [grey levels]: sim.sensors_camera's measure of a scaled frame."""
    return float(np.abs(a - b).mean())


def detail(a: np.ndarray) -> float:
    """Mean |horizontal gradient| [grey levels per px]: what a smaller render loses."""
    return float(np.abs(np.diff(a, axis=1)).mean())


def test_cam_scale_changes_the_detail_not_the_size(window: Window) -> None:
    w = window
    w.run_sim(0.5)  # the car has settled on its wheels
    n = len(w.frames)
    w.until(lambda: "ok" if len(w.frames) >= n + 2 else None, "two full-scale frames")
    full_a, full_b = w.frames[-2][1], w.frames[-1][1]
    w.click(*CAM_SCALE_QUARTER)
    quarter = w.frame_after(w.scale_set("0.25"))
    w.shot("window-view-panel")
    w.click(*CAM_SCALE_FULL)
    full_c = w.frame_after(w.scale_set("1.00"))
    noise = differ(full_a, full_b)
    print(f"full-scale frames differ by {noise:.2f} grey levels; at 0.25 by "
          f"{differ(quarter, full_b):.2f}; back at 1 by {differ(full_c, full_b):.2f}; detail "
          f"{detail(full_b):.2f} at 1, {detail(quarter):.2f} at 0.25")  # fmt: skip
    assert len(w.sizes) == 1, f"the frames changed size: {w.sizes}"
    assert quarter.shape == full_b.shape
    assert differ(quarter, full_b) > max(3 * noise, 0.3), "Cam scale 0.25 changed no pixels"
    assert detail(quarter) < 0.9 * detail(full_b), "Cam scale 0.25 kept all the detail"
    assert differ(full_c, full_b) < differ(quarter, full_b) / 3, "back at 1 is not full scale"
    w.xdotool("key", "--window", w.wid, "Escape")
    assert w.sim is not None and w.sim.wait(timeout=GUARD_S) == 0
