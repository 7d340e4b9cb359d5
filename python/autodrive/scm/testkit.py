"""Running the SCM from tests and benchmarks: autodrive-scm as a real process, an HTTP client
with its session and CSRF token, a throw-away PostgreSQL server (Debian's) and headless
Chromium (Debian's, through chromedriver and Selenium)."""

from __future__ import annotations

import json
import os
import pwd
import shutil
import socket
import ssl
import subprocess
import sys
import tempfile
import http.client
import urllib.error
import urllib.parse
import urllib.request
from http.cookiejar import CookieJar
from pathlib import Path
from typing import Any

from autodrive.core.proc import third_party_env

PG_BIN = Path("/usr/lib/postgresql/15/bin")


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def scm_command(*args: str) -> list[str]:
    return [sys.executable, "-m", "autodrive.scm.cli", *args]


def add_user(db: str, name: str, role: str, password: str) -> None:
    subprocess.run(
        scm_command("user", "add", name, "--role", role, "--db", db, "--password-stdin"),
        input=password + "\n",
        text=True,
        check=True,
        capture_output=True,
    )


class Server:
    """autodrive-scm on Tiny Town on a free port; waits for its "SCM ready" line."""

    def __init__(
        self,
        db: str,
        lcm_url: str,
        build: str,
        vehicles: str = "NIGEL1,NIGEL2,NIGEL3",
        extra: list[str] | None = None,
        port: int | None = None,
        tls: tuple[Path, Path] | None = None,
    ) -> None:
        self.port = port or free_port()
        self.url = f"{'https' if tls else 'http'}://127.0.0.1:{self.port}"
        if tls:
            extra = [*(extra or []), "--tls-cert", str(tls[0]), "--tls-key", str(tls[1])]
        self.log = open(f"/tmp/scm-{self.port}.log", "w")
        cmd = scm_command(
            "--map", "tiny_town", "--db", db, "--host", "127.0.0.1", "--port", str(self.port),
            "--lcm-url", lcm_url, "--vehicles", vehicles, "--build", build, *(extra or []),
        )  # fmt: skip
        self.proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=self.log, text=True)
        assert self.proc.stdout is not None
        line = self.proc.stdout.readline()
        if f"SCM ready {self.url}/" not in line:
            self.stop()
            raise RuntimeError(f"autodrive-scm did not start: {line!r}; log {self.log.name}")

    def stop(self, kill: bool = False) -> int:
        if self.proc.poll() is None:
            if kill:
                self.proc.kill()
            else:
                self.proc.terminate()
        rc = self.proc.wait(timeout=30)
        self.log.close()
        return rc


def self_signed_cert(folder: Path, host: str = "127.0.0.1") -> tuple[Path, Path]:
    """A throw-away self-signed certificate for host (openssl): (cert.pem, key.pem)."""
    cert, key = folder / "cert.pem", folder / "key.pem"
    subprocess.run(
        ["openssl", "req", "-x509", "-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:P-256",
         "-nodes", "-days", "2", "-subj", f"/CN={host}", "-addext", f"subjectAltName=IP:{host}",
         "-keyout", str(key), "-out", str(cert)],
        check=True, capture_output=True,
    )  # fmt: skip
    return cert, key


class Client:
    """An HTTP client with its own cookie jar and the CSRF token of its session (cafile: the
    certificate to trust for https)."""

    def __init__(self, base: str, cafile: Path | None = None) -> None:
        self.base = base
        self.cookies = CookieJar()
        handlers: list[Any] = [urllib.request.HTTPCookieProcessor(self.cookies)]
        if cafile is not None:
            context = ssl.create_default_context(cafile=str(cafile))
            handlers.append(urllib.request.HTTPSHandler(context=context))
        self.opener = urllib.request.build_opener(*handlers)
        self.csrf = ""
        self.last_headers: dict[str, str] = {}

    def call(self, method: str, path: str, body: Any = None, csrf: bool = True) -> tuple[int, Any]:
        data = json.dumps(body).encode() if body is not None else None
        req = urllib.request.Request(self.base + path, data=data, method=method)
        req.add_header("Content-Type", "application/json")
        if csrf and self.csrf:
            req.add_header("X-CSRF-Token", self.csrf)
        try:
            with self.opener.open(req, timeout=60) as r:
                self.last_headers = {k.lower(): v for k, v in r.headers.items()}
                body = r.read()
                is_json = "json" in r.headers.get("content-type", "")
                return int(r.status), json.loads(body or b"null") if is_json else body
        except urllib.error.HTTPError as err:
            self.last_headers = {k.lower(): v for k, v in err.headers.items()}
            return int(err.code), json.loads(err.read() or b"null")

    def login(self, name: str, password: str) -> dict[str, str]:
        code, body = self.call("POST", "/api/login", {"name": name, "password": password})
        if code != 200:
            raise RuntimeError(f"login as {name} failed: {code} {body}")
        self.csrf = str(body["csrf"])
        return dict(body)


class Postgres:
    """A throw-away PostgreSQL server (Debian's) in a temp folder on a free port; as root it
    runs as the 'postgres' user (initdb refuses root). Trust auth, on 127.0.0.1 only."""

    def __init__(self, tmp: str | None = None) -> None:
        self.own = tmp is None  # a folder of its own (readable by 'postgres'), removed at stop
        tmp = tmp or tempfile.mkdtemp(prefix="scm-pg-")
        self.tmp = tmp
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
        opts = f"-p {self.port} -k {self.dir} -c listen_addresses=127.0.0.1"
        self._run([str(PG_BIN / "pg_ctl"), "-D", str(self.dir), "-l", str(self.dir / "log"),
                   "-w", "-t", "60", "-o", opts, "start"])  # fmt: skip
        self.url = f"postgresql://scm@127.0.0.1:{self.port}/postgres"

    def _run(self, cmd: list[str]) -> None:
        # PostgreSQL is no part of the build under test: without the test's LD_PRELOAD of the
        # sanitizer runtime (meant for the SCM's cffi libraries), under which it hangs.
        r = subprocess.run(self.prefix + cmd, capture_output=True, text=True, env=third_party_env())
        if r.returncode != 0:
            raise RuntimeError(f"{' '.join(cmd[:2])} failed: {r.stdout}{r.stderr}")

    def stop(self) -> None:
        self._run([str(PG_BIN / "pg_ctl"), "-D", str(self.dir), "-m", "fast", "-w", "stop"])
        if self.own:
            shutil.rmtree(self.tmp, ignore_errors=True)


def chromium() -> Any:
    """Debian's Chromium, headless, driven through Debian's chromedriver (Selenium). The window
    is tall enough to show the whole map (W3C pointer offsets are from the centre of an
    element's visible part)."""
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    opts = webdriver.ChromeOptions()
    opts.binary_location = "/usr/bin/chromium"
    for arg in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--disable-gpu",
                "--window-size=1600,1300"):  # fmt: skip
        opts.add_argument(arg)
    # The browser is no part of the build under test: no sanitizer runtime preloaded into it (a
    # test's LD_PRELOAD for the SCM's cffi libraries makes chromedriver exit at start).
    return webdriver.Chrome(
        options=opts, service=Service("/usr/bin/chromedriver", env=third_party_env())
    )


def login_page(driver: Any, base: str, name: str, password: str) -> None:
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import WebDriverWait

    driver.get(base + "/")
    WebDriverWait(driver, 20).until(lambda d: d.find_element(By.ID, "login-name").is_displayed())
    driver.find_element(By.ID, "login-name").send_keys(name)
    driver.find_element(By.ID, "login-password").send_keys(password)
    driver.find_element(By.ID, "login-submit").click()
    WebDriverWait(driver, 20).until(lambda d: d.find_element(By.ID, "app").is_displayed())
    # the tables are built from the first live state (WebSocket)
    WebDriverWait(driver, 20).until(lambda d: d.execute_script("return scm.state !== null;"))
    WebDriverWait(driver, 20).until(lambda d: d.find_elements(By.ID, "light-row-1"))


def click_light(driver: Any, light_id: int) -> None:
    """A real pointer click on the light's lamp on the map."""
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By

    canvas = driver.find_element(By.ID, "map")
    u, v = driver.execute_script(f"return scm.lightPixel({light_id});")
    w, h = canvas.size["width"], canvas.size["height"]
    ActionChains(driver).move_to_element_with_offset(
        canvas, int(u - w / 2), int(v - h / 2)
    ).click().perform()


class Attacker:
    """A scripted login brute force from its own loopback address (source 127.0.0.2, so the
    per-address limit it meets is its own): guesses passwords of one account over one kept-alive
    connection, and counts the answers by status."""

    def __init__(self, base: str, cafile: Path | None = None, source: str = "127.0.0.2") -> None:
        parts = urllib.parse.urlsplit(base)
        host, port = parts.hostname or "127.0.0.1", parts.port or 80
        if parts.scheme == "https":
            context = ssl.create_default_context(cafile=str(cafile) if cafile else None)
            self.conn: http.client.HTTPConnection = http.client.HTTPSConnection(
                host, port, context=context, source_address=(source, 0), timeout=60
            )
        else:
            self.conn = http.client.HTTPConnection(
                host, port, source_address=(source, 0), timeout=60
            )

    def guess(self, name: str, password: str) -> int:
        body = json.dumps({"name": name, "password": password})
        self.conn.request("POST", "/api/login", body, {"Content-Type": "application/json"})
        r = self.conn.getresponse()
        r.read()
        return int(r.status)

    def brute_force(self, name: str, passwords: list[str]) -> dict[int, int]:
        counts: dict[int, int] = {}
        for p in passwords:
            status = self.guess(name, p)
            counts[status] = counts.get(status, 0) + 1
        return counts

    def close(self) -> None:
        self.conn.close()
