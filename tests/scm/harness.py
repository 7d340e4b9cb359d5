"""Shared by the SCM tests: start autodrive-scm as a real process (its own SQLite or a given
URL, a free HTTP port, real LCM on the test's UDP port), log in over HTTP, publish poses."""

from __future__ import annotations

import json
import os
import socket
import subprocess
import sys
import time
import urllib.error
import urllib.request
from http.cookiejar import CookieJar
from pathlib import Path
from typing import Any

from autodrive.scm.light_watch import LightWatch  # noqa: F401  (re-exported)
from autodrive.scm.testkit import (  # noqa: F401  (re-exported for the tests)
    Client,
    Postgres,
    Server,
    add_user,
    chromium,
    click_light,
    free_port,
    login_page,
)

ROOT = Path(__file__).resolve().parents[2]
PY = str(ROOT / ".venv" / "bin" / "python")


def check(cond: bool, what: str) -> None:
    assert cond, f"FAIL: {what}"
    print(f"ok: {what}", flush=True)


def wait_for(pred: Any, timeout_s: float, what: str) -> None:
    end = time.time() + timeout_s
    while time.time() < end:
        if pred():
            print(f"ok: {what}", flush=True)
            return
        time.sleep(0.05)
    check(False, what)


os.environ.setdefault("PYTHONUNBUFFERED", "1")


class CarFeeder:
    """Publishes the EKF poses (POSE_MAP) of cars driving routes at a steady speed, 50 Hz."""

    def __init__(self, lc: Any, types: Any, cars: dict[str, tuple[str, float]], speed_m_s: float) -> None:  # fmt: skip
        import threading

        from autodrive import maps
        from autodrive.core.channels import channel

        m = maps.load("tiny_town")
        self.routes = {v: (m.route(r), s0) for v, (r, s0) in cars.items()}
        self.lc, self.T, self.speed = lc, types, speed_m_s
        self.channel = channel
        self.stop_flag = threading.Event()
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _run(self) -> None:
        t0 = time.time()
        while not self.stop_flag.is_set():
            t = time.time() - t0
            for v, (route, s0) in self.routes.items():
                p = route.pose_at((s0 + self.speed * t) % route.length_m)
                o = self.T.odometry_t()
                o.utime, o.vehicle, o.frame_id = int(time.time() * 1e6), v, "map"
                o.x_m, o.y_m, o.yaw_rad, o.vx_m_s = p.x_m, p.y_m, p.yaw_rad, self.speed
                self.lc.publish(self.channel("POSE_MAP", v), o.encode())
            time.sleep(0.02)

    def stop(self) -> None:
        self.stop_flag.set()
        self.thread.join()


def start_sim(
    build: str, lcm_url: str, run_dir: str, cars: int = 3, rtf: float = 1.0
) -> subprocess.Popen[str]:
    """autodrive-sim on Tiny Town at rtf times real time, no window, no ptys: its lights and
    SIM_CLOCK on LCM."""
    return subprocess.Popen(
        [f"{build}/bin/autodrive-sim", "--map", "tiny_town", "--cars", str(cars), "--rtf", str(rtf),
         "--no-pty", "--no-lidar", "--quiet", "--run-dir", run_dir, "--lcm-url", lcm_url],
        stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)  # fmt: skip
