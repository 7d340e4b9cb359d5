"""What the window tests (test_window.py, test_window_manual.py) share: a private Xvfb display,
autodrive-sim --view on it with its stdout lines, the window found by its title, the bus, the
screen grabbed with ffmpeg (x11grab), and waits that pump all of these. The waits are guards on
wall time that fail with what was seen, never pass criteria."""

from __future__ import annotations

import math
import os
import select
import shutil
import signal
import subprocess
import time
from collections.abc import Callable
from pathlib import Path

import pytest
import yaml

from autodrive.core import lcmtypes
from autodrive.core.channels import channel, vehicle_name
from autodrive.core.settings import RUNTIME_HIL_CONFIG

WIN_W, WIN_H = 800, 600  # [px] --view-size: small, for llvmpipe on a busy CPU
GUARD_S = 240.0  # [s] wall: a guard against a hung run, never a pass criterion
PUMP_S = 0.5  # [s] wall: the longest one pump reads before its caller looks again
XVFB_UP_S = 30.0  # [s] wall: a guard for Xvfb's socket (glfwInit failed once before it was up)
WINDOW_TITLE = "AutoDRIVE Nigel sim"
# [px] the Car section's Driving radio (tests/sim_sensors checks the layout)
MANUAL_RADIO = (210, 197)
AUTONOMOUS_RADIO = (145, 197)
AUTHORITY_PERSON = 2  # vehicle_command_t.AUTHORITY_PERSON
DRIVE_M = 0.3  # [m] forward along the start heading: the car drove

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

    def stop_sim_and_display(self) -> int:
        """Stops the simulator as Ctrl-C does, then Xvfb; the simulator's exit code."""
        assert self.sim is not None
        interrupt(self.sim)
        self.close_display()
        return int(self.sim.returncode)


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


class BridgeRig(WindowRig):
    """Xvfb, the simulator's window with its ptys (and extra, its further arguments), the
    runtime's bridge on the Nano pty, and the bus: the ground truth, the commands and the
    lease of NIGEL1."""

    def __init__(
        self, build: Path, tmp: Path, url: str, display_offset: int, extra: list[str]
    ) -> None:
        super().__init__(build, tmp, url, display_offset)
        veh = vehicle_name(1)
        # ground truth: (t [s], x, y [m], yaw [rad], v [m/s])
        self.commands: list[tuple[str, int, bool, float]] = []  # (source, authority, engaged, thr)
        self.holder: list[str] = []
        self.lc.subscribe(channel("GROUND_TRUTH", veh), self._on_truth)
        self.lc.subscribe(channel("COMMAND", veh), self._on_command)
        self.lc.subscribe(channel("CONTROL", veh), self._on_control)
        self.hud_log = tmp / "hud.log"
        run_dir = tmp / "run"
        self.start_sim(
            [str(build / "bin" / "autodrive-sim"), "--view", "--view-size", f"{WIN_W}x{WIN_H}",
             "--no-lidar", "--rtf", "1", "--duration", "3600", "--run-dir", str(run_dir),
             "--lcm-url", url, "--hud-log", str(self.hud_log), "--quiet", *extra],
        )  # fmt: skip
        self.until(lambda: "ok" if (run_dir / "nigel1-nano").exists() else None, "the Nano's pty")
        cfg = yaml.safe_load(RUNTIME_HIL_CONFIG.read_text())
        cfg.update(lcm_url=url)
        cfg["bridge"]["device"] = str(run_dir / "nigel1-nano")
        (tmp / "runtime.yaml").write_text(yaml.safe_dump(cfg))
        self.runtime_log = open(tmp / "runtime.log", "w")
        self.runtime = subprocess.Popen(
            [str(build / "bin" / "autodrive-runtime"), "--config", str(tmp / "runtime.yaml"),
             "--only", "bridge"], stdout=self.runtime_log, stderr=subprocess.STDOUT,
        )  # fmt: skip
        self.wid = self.until(self.window_id, "the window to appear")

    def _on_truth(self, _c: str, data: bytes) -> None:
        m = self.types.ground_truth_t.decode(data)
        self.truth.append((m.utime * 1e-6, m.position_m[0], m.position_m[1], m.yaw_rad,
                           m.linear_velocity_m_s[0]))  # fmt: skip

    def _on_command(self, _c: str, data: bytes) -> None:
        m = self.types.vehicle_command_t.decode(data)
        self.commands.append((m.source, m.authority, bool(m.engaged), m.throttle))

    def _on_control(self, _c: str, data: bytes) -> None:
        self.holder.append(self.types.control_status_t.decode(data).holder)

    def details(self) -> str:
        return (f"; holders: {self.holder[-3:]}; commands: {self.commands[-3:]}; "
                f"truth: {self.truth[-1:]}")  # fmt: skip

    def click(self, x: int, y: int) -> None:
        self.xdotool("mousemove", "--window", self.wid, str(x), str(y), "click", "1")

    def hud(self) -> list[tuple[float, dict[str, str]]]:
        """The HUD of every frame drawn so far: (sim time [s], {title: value})."""
        rows = []
        for line in self.hud_log.read_text().splitlines():
            f = line.split("\t")
            if len(f) < 2:
                continue
            rows.append((int(f[0]) * 1e-6, dict(kv.split("=", 1) for kv in f[1:] if "=" in kv)))
        return rows

    def ahead_of_here(self) -> Callable[[], float]:
        """How far the car has come since now along its heading now [m], as a function."""
        _, x0, y0, yaw0, _ = self.truth[-1]
        c, s = math.cos(yaw0), math.sin(yaw0)
        return lambda: (self.truth[-1][1] - x0) * c + (self.truth[-1][2] - y0) * s

    def close(self) -> int:
        assert self.sim is not None
        for p in (self.sim, self.runtime):
            interrupt(p)
        self.runtime_log.close()
        self.close_display()
        return int(self.sim.returncode)
