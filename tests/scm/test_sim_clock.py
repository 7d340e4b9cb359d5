"""autodrive-scm --clock sim: the lights' yellow and all-red last their time on the simulator's
clock (SIM_CLOCK), not on this machine's, however fast the simulator runs (in the smart-city
mission it runs in lockstep: at half real time on a loaded machine, a yellow of 2 s of wall time
was 1 s in the simulated town). The real autodrive-sim on Tiny Town at 0.5x real time; the
operator turns light 1 GREEN and then RED: the simulator's TRAFFIC_LIGHT_STATE (stamped in sim
time) shows the YELLOW for the light's yellow time of sim time (2 s, 4 s of wall time).
Args: ROOT BUILD PORT."""

from __future__ import annotations

import tempfile
import threading
import time
from pathlib import Path

from harness import Client, Server, add_user, check, start_sim, wait_for

from autodrive.core import lcmtypes
from autodrive import maps
from autodrive.core.channels import channel


def test_yellow_lasts_on_sim_clock(
    root: Path, build_dir: Path, lcm_port: int, lcm_url: str
) -> None:
    root, build, port = str(root), str(build_dir), lcm_port
    url = lcm_url
    T = lcmtypes.load(build)
    S = T.traffic_light_state_t
    RTF = 0.5
    lc = lcmtypes.bus(url)
    states: list[tuple[float, float, int, int]] = []  # (wall received, sim stamp [s], light, state)

    def on_state(_c: str, d: bytes) -> None:
        m = S.decode(d)
        states.append((time.time(), m.utime * 1e-6, int(m.light_id), int(m.state)))

    lc.subscribe(channel("TRAFFIC_LIGHT_STATE"), on_state)
    stop = threading.Event()
    threading.Thread(target=lambda: [lc.handle_timeout(20) for _ in iter(stop.is_set, True)],
                     daemon=True).start()  # fmt: skip
    m = maps.load("tiny_town")
    yellow_s = next(t for t in m.lights() if t.id == 1).program.yellow_s

    def latest(light: int) -> int | None:
        return next((st for _, _, i, st in reversed(states) if i == light), None)

    def first(light: int, state: int, after_wall: float) -> tuple[float, float] | None:
        """(wall, sim stamp) of the light's first message in state at or after after_wall."""
        return next(((w, ts) for w, ts, i, st in list(states)
                     if w >= after_wall and i == light and st == state), None)  # fmt: skip

    with tempfile.TemporaryDirectory(prefix="scm-clock-") as tmp:
        db = f"sqlite:///{tmp}/scm.sqlite"
        add_user(db, "op1", "operator", "operator-pass")
        sim = start_sim(build, url, tmp, rtf=RTF)
        srv = Server(db, url, build, "NIGEL1", extra=["--clock", "sim"])
        try:
            wait_for(lambda: latest(1) is not None, 30, "the simulator publishes light states")
            op = Client(srv.url)
            op.login("op1", "operator-pass")
            check(op.call("PUT", "/api/junctions/x/mode", {"mode": "manual"})[0] == 200, "manual")
            for light in (1, 2, 4):
                code, body = op.call("PUT", f"/api/lights/{light}/state", {"state": "RED"})
                check(code == 200, f"light {light} RED: {body}")
            wait_for(lambda: all(latest(i) == S.RED for i in (1, 2, 4)), 30,
                     "lights 1, 2 and 4 RED in the simulator")  # fmt: skip
            t_ask = time.time()
            code, body = op.call("PUT", "/api/lights/1/state", {"state": "GREEN"})
            check(code == 200, f"light 1 GREEN asked: {body}")
            wait_for(
                lambda: first(1, S.GREEN, t_ask) is not None, 30, "light 1 GREEN in the simulator"
            )
            time.sleep(1.0)
            t_red = time.time()
            code, body = op.call("PUT", "/api/lights/1/state", {"state": "RED"})
            check(code == 200, f"light 1 RED asked: {body}")
            wait_for(lambda: first(1, S.RED, t_red) is not None, 30, "light 1 RED in the simulator")
            y, r = first(1, S.YELLOW, t_red), first(1, S.RED, t_red)
            check(y is not None and r is not None, "light 1 went GREEN -> YELLOW -> RED")
            assert y is not None and r is not None
            sim_yellow, wall_yellow = r[1] - y[1], r[0] - y[0]
            # 0.1 s: the SCM's control step (50 ms wall) is 25 ms of sim time here, plus LCM's
            # way there and back; on the wall clock the yellow would be 1 s of sim time
            check(
                abs(sim_yellow - yellow_s) < 0.1,
                f"the yellow lasted {sim_yellow:.3f} s of sim time ({wall_yellow:.2f} s wall at "
                f"{RTF}x real time); the light's yellow is {yellow_s:g} s",
            )
        finally:
            stop.set()
            rc = srv.stop()
            sim.terminate()
            sim.wait(timeout=30)
        check(rc == 0, f"autodrive-scm stopped cleanly on SIGTERM (rc {rc})")
    print("OK")
