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
            return
        time.sleep(0.05)
    check(False, what)


os.environ.setdefault("PYTHONUNBUFFERED", "1")
