"""The smart-city mission's start-up wait (autodrive.core.proc.wait_ready with the mission's
readiness probe of autodrive-scm), on real processes: the real autodrive-scm is ready (GET
/api/status says ready) and the wait returns the CPU time its start took; one whose port is
taken exits, and the wait says so with its log; a program that never gets ready while it burns
CPU fails on its CPU budget, and one that sleeps on the wall-time guard, each error naming the
CPU and wall time, the load, the last probe and the end of its log. Args: ROOT BUILD PORT."""

from __future__ import annotations

import socket
import sys
import tempfile
from pathlib import Path

from autodrive.hil.missions.smart_city import scm_ready
from autodrive.core.proc import ProcessGroup, wait_ready


def test_startup_wait_bounded_by_cpu_time(
    root: Path, build_dir: Path, lcm_port: int, lcm_url: str
) -> None:
    build, port = str(build_dir), lcm_port
    url = lcm_url
    PY = sys.executable

    def check(cond: bool, what: str) -> None:
        assert cond, f"FAIL: {what}"
        print(f"ok: {what}", flush=True)

    def free_port() -> int:
        with socket.socket() as s:
            s.bind(("127.0.0.1", 0))
            return int(s.getsockname()[1])

    def scm(tmp: Path, http_port: int) -> list[object]:
        return [PY, "-m", "autodrive.scm.cli", "--map", "tiny_town", "--db",
                f"sqlite:///{tmp}/scm.sqlite", "--port", http_port, "--lcm-url", url,
                "--build", build]  # fmt: skip

    def failure(procs: ProcessGroup, name: str, argv: list[object], log: Path, **kw: float) -> str:
        """The error of a wait that must fail."""
        proc = procs.start(name, argv, log)
        try:
            wait_ready(name, proc, lambda: "never ready", procs, kw["cpu"], kw["wall"], print, log)
        except RuntimeError as err:
            return str(err)
        finally:
            procs.stop_all()
        return ""

    with tempfile.TemporaryDirectory(prefix="city-start-") as d:
        tmp = Path(d)
        procs = ProcessGroup(print)
        http_port = free_port()
        base = f"http://127.0.0.1:{http_port}/"
        check(scm_ready(base) is not None, "nothing listens yet: not ready")
        proc = procs.start("autodrive-scm", scm(tmp, http_port), tmp / "scm.log")
        try:
            cpu = wait_ready("autodrive-scm", proc, lambda: scm_ready(base), procs, 30.0, 300.0,
                             print, tmp / "scm.log")  # fmt: skip
            check(0.0 < cpu < 30.0, f"autodrive-scm ready after {cpu:.2f} s of its CPU")
            # a second server on the same port cannot listen: it exits, and the wait says so
            other = ProcessGroup(print)
            (tmp / "b").mkdir()
            p2 = other.start("autodrive-scm-2", scm(tmp / "b", http_port), tmp / "scm2.log")
            try:
                wait_ready("autodrive-scm-2", p2, lambda: "never", other, 30.0, 300.0, print,
                           tmp / "scm2.log")  # fmt: skip
                err = ""
            except RuntimeError as e:
                err = str(e)
            finally:
                other.stop_all()
            check("autodrive-scm-2 exited with code" in err and "already in use" in err,
                  f"a server that cannot listen: {err}")  # fmt: skip
        finally:
            procs.stop_all()
        busy = [PY, "-c", "print('starting', flush=True)\nwhile True: pass"]
        err = failure(procs, "busy", busy, tmp / "busy.log", cpu=1.0, wall=300.0)
        check(
            "busy not ready within 1 s of its CPU time" in err and "load average" in err
            and "last probe: never ready" in err and "starting" in err,
            f"never ready while burning CPU: {err}",
        )  # fmt: skip
        err = failure(procs, "sleeper", ["sleep", "600"], tmp / "sleep.log", cpu=30.0, wall=2.0)
        check("the 2 s wall-time guard" in err and "(empty)" in err, f"never ready, asleep: {err}")
    print("OK")
