"""Two users on one machine (issue 39, point 7): each session is an instance (AUTODRIVE_INSTANCE
or --instance) with its own LCM port and web port, so an SCM on one instance never commands
another instance's lights, and a taken web port says which port and how to pick another.

Side by side, two real autodrive-sim on Tiny Town (instance A from the environment, instance B
from --instance), and an SCM on instance A on its instance's own web port (no --port, no
--lcm-url). The operator puts light 1 RED: the commands appear on A's bus, A's simulator shows
RED, and B's bus carries no TRAFFIC_LIGHT_COMMAND at all. A second SCM on instance A fails with
exit 2 and a message naming the port and AUTODRIVE_INSTANCE (never a bare [Errno 98]). The
instances (41, 42) are far from every test's own port."""

from __future__ import annotations

import os
import subprocess
import tempfile
import time
from pathlib import Path
from typing import Any

from harness import Client, LightWatch, add_user, check, wait_for

from autodrive.core import channels, lcmtypes
from autodrive.core.channels import channel
from autodrive.core.settings import instance
from autodrive.scm.testkit import scm_command

A, B = 41, 42


def sim(build: Path, run_dir: str, env: dict[str, str], *extra: str) -> subprocess.Popen[str]:
    return subprocess.Popen(
        [str(build / "bin" / "autodrive-sim"), "--map", "tiny_town", "--no-pty", "--no-lidar",
         "--quiet", "--run-dir", run_dir, *extra],
        env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip


def test_two_instances_side_by_side(build_dir: Path) -> None:
    T = lcmtypes.load(build_dir)
    bus_a = lcmtypes.bus(instance(str(A)).lcm_url(channels.load().url_default))
    bus_b = lcmtypes.bus(instance(str(B)).lcm_url(channels.load().url_default))
    commands_b: list[Any] = []
    bus_b.subscribe(channel("TRAFFIC_LIGHT_COMMAND"), lambda _c, d: commands_b.append(d))
    commands_a: list[Any] = []
    bus_a.subscribe(channel("TRAFFIC_LIGHT_COMMAND"), lambda _c, d: commands_a.append(d))
    watch_a = LightWatch(bus_a, T)
    watch_b = LightWatch(bus_b, T)
    env_a = {**os.environ, "AUTODRIVE_INSTANCE": str(A)}
    env_plain = {k: v for k, v in os.environ.items() if k != "AUTODRIVE_INSTANCE"}
    web_a = instance(str(A)).web_port()
    procs: list[subprocess.Popen[str]] = []
    with tempfile.TemporaryDirectory(prefix="scm-inst-") as tmp:
        db = f"sqlite:///{tmp}/scm.sqlite"
        add_user(db, "op1", "operator", "operator-pass")
        try:
            procs.append(sim(build_dir, f"{tmp}/a", env_a))
            procs.append(sim(build_dir, f"{tmp}/b", env_plain, "--instance", str(B)))
            wait_for(lambda: watch_a.latest(1) is not None and watch_b.latest(1) is not None, 60,
                     "both simulators publish light states, each on its own instance's bus")  # fmt: skip
            cmd = scm_command("--map", "tiny_town", "--db", db, "--build", str(build_dir))
            scm = subprocess.Popen(cmd, env=env_a, stdout=subprocess.PIPE,
                                   stderr=subprocess.PIPE, text=True)  # fmt: skip
            procs.append(scm)
            assert scm.stdout is not None
            line = scm.stdout.readline()
            check(f"SCM ready http://127.0.0.1:{web_a}/" in line,
                  f"the SCM of instance {A} serves on its instance's web port: {line.strip()}")  # fmt: skip

            second = subprocess.run(cmd, env=env_a, capture_output=True, text=True, timeout=120)
            print(second.stderr.strip())
            check(second.returncode == 2, f"a second SCM on instance {A} exits 2")
            check(str(web_a) in second.stderr and "AUTODRIVE_INSTANCE" in second.stderr
                  and "Errno" not in second.stderr,
                  "its error names the port and how to pick another instance")  # fmt: skip

            op = Client(f"http://127.0.0.1:{web_a}")
            op.login("op1", "operator-pass")
            code, body = op.call("PUT", "/api/junctions/x/mode", {"mode": "manual"})
            check(code == 200, f"junction x manual: {code} {body}")
            code, body = op.call("PUT", "/api/lights/1/state", {"state": "RED"})
            check(code == 200, f"light 1 RED: {code} {body}")
            S = T.traffic_light_state_t
            wait_for(lambda: watch_a.latest(1) == S.RED and commands_a, 30,
                     f"instance {A}'s simulator obeys its SCM (light 1 RED)")  # fmt: skip
            time.sleep(1.0)  # any stray command on B's bus would have arrived by now
            check(not commands_b, f"instance {B}'s bus carried no light command: {len(commands_b)}")
        finally:
            for p in procs:
                p.terminate()
            for p in procs:
                try:
                    p.wait(timeout=30)
                except subprocess.TimeoutExpired:
                    p.kill()
