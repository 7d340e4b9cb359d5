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

ROOT = Path(__file__).resolve().parents[2]
PY = str(ROOT / ".venv" / "bin" / "python")


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def add_user(db: str, name: str, role: str, password: str) -> None:
    subprocess.run(
        [
            PY,
            "-m",
            "autodrive_tools.scm.cli",
            "user",
            "add",
            name,
            "--role",
            role,
            "--db",
            db,
            "--password-stdin",
        ],
        input=password + "\n",
        text=True,
        check=True,
        capture_output=True,
    )


class Server:
    def __init__(
        self,
        db: str,
        lcm_url: str,
        build: str,
        vehicles: str = "NIGEL1,NIGEL2,NIGEL3",
        extra: list[str] | None = None,
        port: int | None = None,
    ) -> None:
        self.port = port or free_port()
        self.url = f"http://127.0.0.1:{self.port}"
        self.log = open(f"/tmp/scm-test-{self.port}.log", "w")
        self.proc = subprocess.Popen(
            [
                PY,
                "-m",
                "autodrive_tools.scm.cli",
                "--map",
                "tiny_town",
                "--db",
                db,
                "--host",
                "127.0.0.1",
                "--port",
                str(self.port),
                "--lcm-url",
                lcm_url,
                "--vehicles",
                vehicles,
                "--build",
                build,
                *(extra or []),
            ],
            stdout=subprocess.PIPE,
            stderr=self.log,
            text=True,
        )
        assert self.proc.stdout is not None
        line = self.proc.stdout.readline()
        if f"SCM ready {self.url}/" not in line:
            self.stop()
            raise RuntimeError(f"autodrive-scm did not start: {line!r}; log {self.log.name}")

    def stop(self, sig: str = "term") -> int:
        if self.proc.poll() is None:
            (self.proc.kill if sig == "kill" else self.proc.terminate)()
        rc = self.proc.wait(timeout=20)
        self.log.close()
        return rc


class Client:
    """An HTTP client with its own cookie jar and the CSRF token of its session."""

    def __init__(self, base: str) -> None:
        self.base = base
        self.jar = CookieJar()
        self.opener = urllib.request.build_opener(urllib.request.HTTPCookieProcessor(self.jar))
        self.csrf = ""

    def call(self, method: str, path: str, body: Any = None, csrf: bool = True) -> tuple[int, Any]:
        data = json.dumps(body).encode() if body is not None else None
        req = urllib.request.Request(self.base + path, data=data, method=method)
        req.add_header("Content-Type", "application/json")
        if csrf and self.csrf:
            req.add_header("X-CSRF-Token", self.csrf)
        try:
            with self.opener.open(req, timeout=60) as r:
                return r.status, json.loads(r.read() or b"null")
        except urllib.error.HTTPError as err:
            return err.code, json.loads(err.read() or b"null")

    def login(self, name: str, password: str) -> dict[str, str]:
        code, body = self.call("POST", "/api/login", {"name": name, "password": password})
        assert code == 200, (code, body)
        self.csrf = body["csrf"]
        return dict(body)


def check(cond: bool, what: str) -> None:
    if not cond:
        print(f"FAIL: {what}", flush=True)
        sys.exit(1)
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


PG_BIN = Path("/usr/lib/postgresql/15/bin")


class Postgres:
    """A throw-away PostgreSQL server (Debian's) in a temp folder on a free port; as root it
    runs as the 'postgres' user (initdb refuses root). Trust auth on 127.0.0.1 only."""

    def __init__(self, tmp: str) -> None:
        import pwd
        import shutil

        self.dir = Path(tmp) / "pgdata"
        self.port = free_port()
        self.prefix: list[str] = []
        Path(tmp).mkdir(parents=True, exist_ok=True)
        if os.geteuid() == 0:
            self.prefix = ["runuser", "-u", "postgres", "--"]
            pw = pwd.getpwnam("postgres")
            os.chmod(tmp, 0o755)
            self.dir.mkdir()
            shutil.chown(self.dir, pw.pw_uid, pw.pw_gid)
        self._run([str(PG_BIN / "initdb"), "-D", str(self.dir), "-U", "scm", "--auth=trust",
                   "-E", "UTF8", "--no-sync"])  # fmt: skip
        self._run([str(PG_BIN / "pg_ctl"), "-D", str(self.dir), "-l", str(self.dir / "log"),
                   "-w", "-t", "60", "-o",
                   f"-p {self.port} -k {self.dir} -c listen_addresses=127.0.0.1", "start"])  # fmt: skip
        self.url = f"postgresql://scm@127.0.0.1:{self.port}/postgres"

    def _run(self, cmd: list[str]) -> None:
        r = subprocess.run(self.prefix + cmd, capture_output=True, text=True)
        if r.returncode != 0:
            raise RuntimeError(f"{' '.join(cmd[:2])} failed: {r.stdout}{r.stderr}")

    def stop(self) -> None:
        self._run([str(PG_BIN / "pg_ctl"), "-D", str(self.dir), "-m", "fast", "-w", "stop"])


def chromium() -> Any:
    """Debian's Chromium, headless, driven through Debian's chromedriver (Selenium)."""
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    opts = webdriver.ChromeOptions()
    opts.binary_location = "/usr/bin/chromium"
    for arg in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--disable-gpu",
                "--window-size=1600,1300"):  # fmt: skip
        opts.add_argument(arg)
    return webdriver.Chrome(options=opts, service=Service("/usr/bin/chromedriver"))


class CarFeeder:
    """Publishes the EKF poses (POSE_MAP) of cars driving routes at a steady speed, 50 Hz."""

    def __init__(self, lc: Any, types: Any, cars: dict[str, tuple[str, float]], speed_m_s: float) -> None:  # fmt: skip
        import threading

        from autodrive_tools import maps
        from autodrive_tools.channels import channel

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


class LightWatch:
    """The simulator's TRAFFIC_LIGHT_STATE messages, (wall time received, light id, state)."""

    def __init__(self, lc: Any, types: Any) -> None:
        import threading

        from autodrive_tools.channels import channel

        self.states: list[tuple[float, int, int]] = []
        self.T = types
        lc.subscribe(channel("TRAFFIC_LIGHT_STATE"), self._on)
        self.lc = lc
        self.stop_flag = threading.Event()
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _on(self, _c: str, data: bytes) -> None:
        m = self.T.traffic_light_state_t.decode(data)
        self.states.append((time.time(), m.light_id, m.state))

    def _run(self) -> None:
        while not self.stop_flag.is_set():
            self.lc.handle_timeout(20)

    def latest(self, light_id: int) -> int | None:
        for _, i, s in reversed(self.states):
            if i == light_id:
                return s
        return None

    def first_after(self, light_id: int, state: int, t: float) -> float | None:
        for tr, i, s in list(self.states):
            if tr >= t and i == light_id and s == state:
                return tr
        return None

    def stop(self) -> None:
        self.stop_flag.set()
        self.thread.join()


def start_sim(build: str, lcm_url: str, run_dir: str, cars: int = 3) -> subprocess.Popen[str]:
    """autodrive-sim on Tiny Town at real time, no window, no ptys: its lights on LCM."""
    return subprocess.Popen(
        [f"{build}/bin/autodrive-sim", "--map", "tiny_town", "--cars", str(cars), "--rtf", "1",
         "--no-pty", "--no-lidar", "--quiet", "--run-dir", run_dir, "--lcm-url", lcm_url],
        stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)  # fmt: skip
