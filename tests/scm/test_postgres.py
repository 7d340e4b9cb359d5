"""autodrive-scm on a real PostgreSQL server (Debian's, started here in a temp folder and
stopped at the end): the Alembic migrations create the schema, a user is added on the command
line, poses from LCM (EKF channel) and from REST (acknowledged after commit) are all stored
(rows counted), the event log records the operator's light command with its author, and after
a restart the rows and the operator's program are still there. Bad --db URLs and a broken map
file give clear errors. Args: ROOT BUILD PORT."""

from __future__ import annotations

import subprocess
import tempfile
import time
from pathlib import Path

from harness import PY, Client, Postgres, Server, add_user, check, wait_for

from autodrive.core import lcmtypes
from autodrive.core.channels import channel


def test_scm_on_postgres(root: Path, build_dir: Path, lcm_port: int, lcm_url: str) -> None:
    root, build, port = str(root), str(build_dir), lcm_port
    url = lcm_url
    T = lcmtypes.load(build)
    lc = lcmtypes.bus(url)

    with tempfile.TemporaryDirectory(prefix="scm-pg-") as tmp:
        pg = Postgres(tmp)
        try:
            add_user(pg.url, "op1", "operator", "operator-pass")
            srv = Server(pg.url, url, build, "NIGEL1", ["--history-hz", "0"])
            try:
                op = Client(srv.url)
                op.login("op1", "operator-pass")
                for k in range(100):  # 2 s of one car at 50 Hz on the EKF channel
                    o = T.odometry_t()
                    o.utime, o.vehicle, o.frame_id = 1_000_000 + k * 20_000, "NIGEL1", "map"
                    o.x_m, o.y_m, o.yaw_rad = -3.0 + 0.01 * k, -3.14, 0.0
                    lc.publish(channel("POSE_MAP", "NIGEL1"), o.encode())
                    time.sleep(0.02)
                poses = [{"vehicle": "REST1", "utime": k * 20_000, "x_m": 0.01 * k, "y_m": 0.0,
                          "yaw_rad": 0.0, "seq": k} for k in range(500)]  # fmt: skip
                code, body = op.call("POST", "/api/poses", {"poses": poses})
                check(
                    code == 200 and body["stored"] == 500, f"500 poses acknowledged: {code} {body}"
                )
                code, body = op.call("GET", "/api/poses/count?vehicle=REST1")
                check(
                    body["rows"] == 500, f"all 500 acknowledged rows in PostgreSQL ({body['rows']})"
                )
                wait_for(lambda: op.call("GET", "/api/poses/count?vehicle=NIGEL1")[1]["rows"] == 100, 5,
                         "100 of 100 LCM poses stored (history at every pose)")  # fmt: skip
                code, body = op.call("PUT", "/api/lights/2/program", {"offset_s": 10.0, "phases": [
                    {"state": "GREEN", "duration_s": 5.0}, {"state": "YELLOW", "duration_s": 2.0},
                    {"state": "RED", "duration_s": 13.0}]})  # fmt: skip
                check(code == 200, f"program of light 2 edited: {code} {body}")
                code, body = op.call("PUT", "/api/lights/1/state", {"state": "RED"})
                check(code == 200, f"light 1 set by op1: {body}")
                time.sleep(0.5)
                code, events = op.call("GET", "/api/events")
                mine = [e for e in events if e["actor"] == "op1" and e["kind"] == "light_request"]
                check(bool(mine) and mine[0]["subject"] == "light 1", "event log: op1 set light 1")
            finally:
                check(srv.stop() == 0, "server stopped cleanly")
            srv = Server(
                pg.url, url, build, "NIGEL1"
            )  # the schema is there: migrations are a no-op
            try:
                op = Client(srv.url)
                op.login("op1", "operator-pass")
                code, body = op.call("GET", "/api/poses/count")
                check(body["rows"] == 600, f"after a restart: 600 rows ({body['rows']})")
                code, lights = op.call("GET", "/api/lights")
                l2 = next(x for x in lights if x["id"] == 2)
                check(
                    l2["program"]["phases"][0]["duration_s"] == 5.0, "the edited program survived"
                )
            finally:
                srv.stop()
        finally:
            pg.stop()

        def start_fails(args: list[str]) -> str:
            r = subprocess.run([PY, "-m", "autodrive.scm.cli", "--build", build, *args],
                               capture_output=True, text=True, timeout=60)  # fmt: skip
            check(r.returncode == 2, f"exit 2 for {args}: {r.stderr.strip()}")
            return r.stderr

        err = start_fails(["--db", f"postgresql://scm@127.0.0.1:{pg.port}/postgres"])
        check("cannot connect" in err, "a server that is gone: 'cannot connect'")
        err = start_fails(["--db", "mysql://x@localhost/db"])
        check("not supported" in err, "an unsupported backend is named")
        err = start_fails(["--db", "sqlite://"])
        check("give a file" in err, "an in-memory SQLite is refused")
        broken = f"{tmp}/broken.yaml"
        with open(broken, "w") as f:
            f.write("floor_half_size_m: [1, 2\n")
        err = start_fails(["--map", broken, "--db", f"sqlite:///{tmp}/x.sqlite"])
        check("broken.yaml" in err and "not valid YAML" in err, "a broken map file is named")
    print("OK")
