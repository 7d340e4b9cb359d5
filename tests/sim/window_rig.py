"""What the window tests (test_window.py, test_window_manual.py) share: a private Xvfb display,
autodrive-sim --view on it with its stdout lines, the window found by its title, the bus, the
screen grabbed with ffmpeg (x11grab), and waits that pump all of these. The waits are guards on
wall time that fail with what was seen, never pass criteria."""

from __future__ import annotations

import os
import select
import shutil
import signal
import subprocess
import time
from collections.abc import Callable
from pathlib import Path

import pytest

from autodrive.core import lcmtypes

WIN_W, WIN_H = 800, 600  # [px] --view-size: small, for llvmpipe on a busy CPU
GUARD_S = 240.0  # [s] wall: a guard against a hung run, never a pass criterion
PUMP_S = 0.5  # [s] wall: the longest one pump reads before its caller looks again
XVFB_UP_S = 30.0  # [s] wall: a guard for Xvfb's socket (glfwInit failed once before it was up)
WINDOW_TITLE = "AutoDRIVE Nigel sim"

NEEDS_X_TOOLS = pytest.mark.skipif(
    not (shutil.which("Xvfb") and shutil.which("xdotool") and shutil.which("ffmpeg")),
    reason="needs Xvfb, xdotool and ffmpeg (tools/debian-packages.txt)",
)


class WindowRig:
    """Xvfb on a display of its own, the bus and the simulator's window (start_sim)."""

    def __init__(self, build: Path, tmp: Path, url: str, display_offset: int) -> None:
        number = 300 + (os.getpid() + display_offset) % 600
        self.display = f":{number}"
        self.xvfb = subprocess.Popen(
            ["Xvfb", self.display, "-screen", "0", f"{WIN_W}x{WIN_H}x24", "-nolisten", "tcp"],
            stderr=subprocess.DEVNULL,
        )
        self.env = dict(os.environ, DISPLAY=self.display)
        self.types = lcmtypes.load(build)
        self.lc = lcmtypes.bus(url)
        self.tmp = tmp
        self.truth: list[tuple[float, ...]] = []  # ground truth, sim time [s] first
        self.lines: list[str] = []
        self.sim: subprocess.Popen[str] | None = None
        socket = Path(f"/tmp/.X11-unix/X{number}")
        self.until(lambda: "ok" if socket.exists() else None, f"Xvfb's socket {socket}", XVFB_UP_S)

    def start_sim(self, argv: list[str]) -> None:
        self.sim = subprocess.Popen(argv, cwd=self.tmp, env=self.env, stdout=subprocess.PIPE,
                                    text=True)  # fmt: skip

    def details(self) -> str:
        """What a failed wait also reports (a rig adds what it watches)."""
        return ""

    def window_id(self) -> str | None:
        r = subprocess.run(["xdotool", "search", "--name", WINDOW_TITLE],
                           env=self.env, capture_output=True, text=True)  # fmt: skip
        return r.stdout.split()[0] if r.returncode == 0 and r.stdout.split() else None

    def pump(self) -> None:
        """Reads the LCM messages and the program's stdout lines that arrived, for at most
        PUMP_S: a test slower than the bus (a loaded machine) would else never return to its
        guard, and hang past it."""
        deadline = time.monotonic() + PUMP_S
        while time.monotonic() < deadline and select.select([self.lc.fileno()], [], [], 0.02)[0]:
            self.lc.handle()
        if self.sim is None or self.sim.stdout is None:
            return
        while select.select([self.sim.stdout], [], [], 0)[0]:
            line = self.sim.stdout.readline()
            if not line:
                break
            self.lines.append(line.strip())

    def until(self, what: Callable[[], str | None], saying: str, guard_s: float = GUARD_S) -> str:
        t0 = time.monotonic()
        while time.monotonic() - t0 < guard_s:
            self.pump()
            got = what()
            if got:
                return got
            if self.sim is not None:
                assert self.sim.poll() is None, f"the simulator exited ({self.sim.returncode})"
        raise AssertionError(f"waited for {saying}; stdout: {self.lines[-5:]}{self.details()}")

    def sim_time(self) -> float:
        self.pump()
        return self.truth[-1][0] if self.truth else 0.0

    def run_sim(self, seconds: float) -> float:
        """Waits until the sim time has advanced by seconds; returns it."""
        t_end = self.sim_time() + seconds
        self.until(lambda: "ok" if self.sim_time() >= t_end else None, f"sim time {t_end:.1f} s")
        return self.sim_time()

    def xdotool(self, *args: str) -> None:
        subprocess.run(["xdotool", *args], env=self.env, check=True)

    def shot(self, name: str) -> Path:
        """The screen as a PNG, copied to $AUTODRIVE_SCREENSHOT_DIR when set (the docs')."""
        path = self.tmp / f"{name}.png"
        subprocess.run(["ffmpeg", "-v", "error", "-y", "-f", "x11grab", "-video_size",
                        f"{WIN_W}x{WIN_H}", "-i", f"{self.display}+0,0", "-frames:v", "1",
                        str(path)], env=self.env, check=True)  # fmt: skip
        assert path.stat().st_size > 0, path
        out = os.environ.get("AUTODRIVE_SCREENSHOT_DIR")
        if out:
            shutil.copy(path, Path(out) / f"{name}.png")
        return path

    def close_display(self) -> None:
        self.xvfb.terminate()
        self.xvfb.wait()


def interrupt(p: subprocess.Popen[str] | subprocess.Popen[bytes]) -> None:
    """Stops a program as Ctrl-C does, killing it after 60 s of wall time (a hang guard)."""
    if p.poll() is not None:
        return
    p.send_signal(signal.SIGINT)
    try:
        p.wait(timeout=60)
    except subprocess.TimeoutExpired:
        p.kill()
        p.wait()
