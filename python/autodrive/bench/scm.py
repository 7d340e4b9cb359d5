"""tools/bench scm: the Smart City Manager (autodrive-scm). Progress on stderr; figures on
stdout, the last line one JSON object. Needs AUTODRIVE_BUILD (LCM types and autodrive-sim).

click_to_light_state_ms_p50 (p90, max): Debian's Chromium (Selenium) logged in as an operator
clicks light 1 on the web app's map, alternately to GREEN and to RED, junction in manual, the
conflicting lights red; from the click (the page's Date.now() in its click handler) to this
process receiving the simulator's TRAFFIC_LIGHT_STATE with the light's first new state (GREEN,
or the enforced YELLOW on the way to RED), over real UDP LCM, autodrive-sim on Tiny Town at
real time. Median of BENCH_SCM_CLICKS (default 20) clicks.
pose_ingest_hz_max_sqlite / _postgresql: the largest number of cars, each sending its EKF
pose (POSE_MAP) at 50 Hz over real UDP LCM for --ingest-s seconds, that the server stores
with nothing lost (history at every pose, --history-hz 0; rows counted in the database =
messages sent) on SQLite (WAL, synchronous=FULL) and on PostgreSQL (Debian's, in a temp
folder); steps --cars (default 25,50,100,200,400), stopping at the first loss. The publisher
is one Python process (each car's message encoded once); a step where it could not keep 95 %
of 50 Hz per car is marked publisher-bound and ends the search. ingest_steps_* lists every step
(cars, sent, received by the server, stored, Hz per car achieved, drain_s: seconds from the
last message until the server had committed everything).
restart_loss_sqlite / _postgresql: a client posts poses in batches of 20 to POST /api/poses
(acknowledged only after commit) as fast as the server acknowledges; after 3 s the server is
killed with SIGKILL mid-run and restarted on the same database; lost = acknowledged poses (by
seq) not in the database. Must be 0. restart_acked_* says how many were acknowledged.
"""

from __future__ import annotations

import argparse
import os
import signal
import statistics
import subprocess
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

from autodrive.core import lcmtypes
from autodrive.core.channels import channel
from autodrive.scm import testkit
from autodrive.scm.light_watch import LightWatch
from autodrive.bench import Progress, build_dir, out_dir, print_figures
from autodrive.core import seeds
from autodrive.bench.goals import at_least, at_most, equals, judge

UNSEEDED = seeds.unseeded("web latencies, ingest rates and restart losses")
GOALS = {
    "click_to_light_state": at_most("click_to_light_state_ms_p50", 100),
    "pose_ingest": at_least("pose_ingest_hz_max", 100),
    "restart_loss": equals("restart_loss", 0),
}

URL = "udpm://239.255.76.67:7796?ttl=0"
log = Progress("scm")
OP = ("bench_op", "bench-operator-pass")


def wait(pred: Any, timeout_s: float, what: str) -> None:
    end = time.time() + timeout_s
    while time.time() < end:
        if pred():
            return
        time.sleep(0.01)
    raise RuntimeError(f"timed out: {what}")


def click_latency(build: Path, clicks: int, shots: Path) -> dict[str, Any]:
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import Select

    T = lcmtypes.load(build)
    S = T.traffic_light_state_t
    with tempfile.TemporaryDirectory(prefix="bench-scm-click-") as tmp:
        db = f"sqlite:///{tmp}/scm.sqlite"
        testkit.add_user(db, OP[0], "operator", OP[1])
        sim = subprocess.Popen(
            [str(build / "bin" / "autodrive-sim"), "--map", "tiny_town", "--rtf", "1",
             "--no-pty", "--no-lidar", "--quiet", "--run-dir", tmp, "--lcm-url", URL],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)  # fmt: skip
        watch = LightWatch(lcmtypes.bus(URL), T, poll_ms=10)
        srv = testkit.Server(db, URL, str(build), "NIGEL1")
        driver = testkit.chromium()
        samples: list[float] = []
        try:
            wait(lambda: watch.latest(1) is not None, 60, "light states from the simulator")
            testkit.login_page(driver, srv.url, *OP)
            Select(driver.find_element(By.ID, "mode-x")).select_by_visible_text("manual")
            for other in (2, 4):
                driver.find_element(By.ID, f"light-{other}-red").click()
            wait(lambda: watch.latest(2) == S.RED and watch.latest(4) == S.RED, 10, "2, 4 red")
            if watch.latest(1) == S.GREEN:
                driver.find_element(By.ID, "light-1-red").click()
                wait(lambda: watch.latest(1) == S.RED, 10, "light 1 red")
            for k in range(clicks):
                want = S.GREEN if k % 2 == 0 else S.YELLOW
                time.sleep(1.3 if want == S.GREEN else 0.5)  # all-red / a moment of green
                before = time.time()
                testkit.click_light(driver, 1)
                wait(lambda: watch.first_after(1, want, before) is not None, 10, "light 1 change")
                got = watch.first_after(1, want, before)
                click = driver.execute_script("return scm.lastClick;")
                assert got is not None and click is not None
                samples.append(got * 1e3 - float(click["t_ms"]))
                if want == S.YELLOW:
                    wait(lambda: watch.latest(1) == S.RED, 10, "light 1 red after yellow")
                log(f"click {k + 1}/{clicks}: {samples[-1]:.1f} ms")
            driver.save_screenshot(str(shots / "bench_scm.png"))
        finally:
            driver.quit()
            srv.stop()
            watch.stop()
            sim.terminate()
            sim.wait(timeout=20)
    samples.sort()
    return {
        "click_to_light_state_ms_p50": round(statistics.median(samples), 1),
        "click_to_light_state_ms_p90": round(samples[int(0.9 * (len(samples) - 1))], 1),
        "click_to_light_state_ms_max": round(samples[-1], 1),
        "clicks": len(samples),
    }


def publish_cars(types: Any, cars: int, seconds: float, prefix: str) -> tuple[int, float]:
    """cars x 50 Hz EKF poses for seconds; returns (messages sent, achieved Hz per car). Each
    car's message is encoded once (its pose and stamp repeat): the publisher, one Python
    process on the same machine, must not be what limits the figure."""
    lc = lcmtypes.bus(URL)
    msgs = []
    for i in range(cars):
        o = types.odometry_t()
        o.utime, o.vehicle, o.frame_id = int(time.time() * 1e6), f"{prefix}{i}", "map"
        o.x_m, o.y_m, o.yaw_rad = 0.0, 0.1 * i, 0.0
        msgs.append((channel("POSE_MAP", f"{prefix}{i}"), o.encode()))
    sent, ticks = 0, 0
    publish = lc.publish
    t0 = time.monotonic()
    while time.monotonic() - t0 < seconds:
        for ch, data in msgs:
            publish(ch, data)
        sent += cars
        ticks += 1
        delay = t0 + ticks * 0.02 - time.monotonic()
        if delay > 0:
            time.sleep(delay)
    return sent, ticks / (time.monotonic() - t0)


def rows(client: testkit.Client) -> int:
    code, body = client.call("GET", "/api/poses/count")
    if code != 200:
        raise RuntimeError(f"GET /api/poses/count: {code} {body}")
    return int(body["rows"])


def server_stats(client: testkit.Client) -> dict[str, Any]:
    code, body = client.call("GET", "/api/status")
    if code != 200:
        raise RuntimeError(f"GET /api/status: {code} {body}")
    stats: dict[str, Any] = body["stats"]
    return stats


def received(client: testkit.Client) -> int:
    return int(server_stats(client)["poses_in"])


def ingest(build: Path, db: str, steps: list[int], seconds: float) -> tuple[int, list[Any]]:
    T = lcmtypes.load(build)
    testkit.add_user(db, OP[0], "operator", OP[1])
    srv = testkit.Server(db, URL, str(build), "NIGEL1", ["--history-hz", "0"])
    best, table = 0, []
    try:
        client = testkit.Client(srv.url)
        client.login(*OP)
        for k, cars in enumerate(steps):
            before, got0 = rows(client), received(client)
            sent, hz = publish_cars(T, cars, seconds, f"B{k}C")
            t_end = time.time()
            deadline = t_end + 120
            while time.time() < deadline:  # until the receiver is idle and the writer is done
                a = server_stats(client)
                time.sleep(0.3)
                b = server_stats(client)
                if a["poses_in"] == b["poses_in"] and b["db_pending"] == 0:
                    break
            drain_s = time.time() - t_end
            stored = rows(client) - before
            bound = hz < 0.95 * 50
            got = received(client) - got0
            table.append({"cars": cars, "sent": sent, "received": got, "stored": stored,
                          "hz_per_car": round(hz, 1), "publisher_bound": bound,
                          "drain_s": round(drain_s, 1)})  # fmt: skip
            log(f"{db.split(':')[0]}: {cars} cars x {hz:.1f} Hz: sent {sent}, received {got}, "
                f"stored {stored}, all committed {drain_s:.1f} s after the last")  # fmt: skip
            if stored != sent or bound:
                break
            best = cars
    finally:
        srv.stop()
    return best, table


def restart_loss(build: Path, db: str) -> tuple[int, int]:
    testkit.add_user(db, OP[0], "operator", OP[1])
    srv = testkit.Server(db, URL, str(build), "NIGEL1")
    acked: set[int] = set()
    stop = threading.Event()

    def feed() -> None:
        client = testkit.Client(srv.url)
        client.login(*OP)
        seq = 0
        while not stop.is_set():
            batch = [{"vehicle": "KILL1", "utime": (seq + i) * 20_000, "x_m": 0.0, "y_m": 0.0,
                      "yaw_rad": 0.0, "seq": seq + i} for i in range(20)]  # fmt: skip
            try:
                code, _ = client.call("POST", "/api/poses", {"poses": batch})
            except OSError:
                return  # the server is gone: this batch was not acknowledged
            if code == 200:
                acked.update(range(seq, seq + 20))
            seq += 20

    t = threading.Thread(target=feed, daemon=True)
    t.start()
    time.sleep(3.0)
    os.kill(srv.proc.pid, signal.SIGKILL)
    stop.set()
    srv.stop()
    t.join(timeout=30)
    srv = testkit.Server(db, URL, str(build), "NIGEL1")
    try:
        client = testkit.Client(srv.url)
        client.login(*OP)
        code, hist = client.call("GET", "/api/vehicles/KILL1/history?limit=100000")
        stored = {int(r["seq"]) for r in hist} if code == 200 else set()
    finally:
        srv.stop()
    lost = len(acked - stored)
    log(f"{db.split(':')[0]}: acknowledged {len(acked)}, stored {len(stored)}, lost {lost}")
    return lost, len(acked)


def main(argv: list[str]) -> int:
    p = argparse.ArgumentParser(prog="tools/bench scm", description=__doc__.split("\n\n")[0])
    p.add_argument("--cars", default="25,50,100,200,400", help="ingest steps [cars]")
    p.add_argument("--ingest-s", type=float, default=10.0, help="seconds per ingest step")
    p.add_argument("--clicks", type=int, default=int(os.environ.get("BENCH_SCM_CLICKS", "20")))
    p.add_argument("--skip-browser", action="store_true", help="(goals_met is then false)")
    p.add_argument("--skip-postgres", action="store_true")
    a = p.parse_args(argv)
    build = build_dir("scm")
    shots = out_dir() / "scm"
    shots.mkdir(parents=True, exist_ok=True)
    steps = [int(c) for c in a.cars.split(",")]
    fig: dict[str, Any] = {}
    if not a.skip_browser:
        log("click -> light state through Chromium, the SCM and autodrive-sim")
        fig.update(click_latency(build, a.clicks, shots))
    with tempfile.TemporaryDirectory(prefix="bench-scm-") as tmp:
        pg = None if a.skip_postgres else testkit.Postgres()
        backends = [("sqlite", f"sqlite:///{tmp}/ingest.sqlite", f"sqlite:///{tmp}/restart.sqlite")]
        if pg is not None:
            backends.append(("postgresql", pg.url, pg.url))
        try:
            for name, ingest_db, restart_db in backends:
                best, table = ingest(build, ingest_db, steps, a.ingest_s)
                fig[f"pose_ingest_hz_max_{name}"] = best
                fig[f"ingest_steps_{name}"] = table
                lost, n = restart_loss(build, restart_db)
                fig[f"restart_loss_{name}"] = lost
                fig[f"restart_acked_{name}"] = n
        finally:
            if pg:
                pg.stop()
    ingest_keys = [k for k in fig if k.startswith("pose_ingest_hz_max_")]
    fig["pose_ingest_hz_max"] = min((fig[k] for k in ingest_keys), default=None)
    losses = [v for k, v in fig.items() if k.startswith("restart_loss_")]
    fig["restart_loss"] = sum(losses) if losses else None
    print_figures(judge(fig, GOALS, UNSEEDED), key_value_lines=True)
    return 0
