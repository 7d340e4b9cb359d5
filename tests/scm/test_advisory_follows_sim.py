"""The V2I advisory never runs ahead of the simulator's light (issue 15: a car stood at a red
light and drove on when the SCM's advisory said green before the simulator's light had turned,
because the SCM advised its own commanded state once the simulator's TRAFFIC_LIGHT_STATE was
late). Against the real autodrive-sim on Tiny Town: NIGEL1's EKF pose stands on north_to_lot
before light 1; the operator puts junction x in manual with lights 1, 2 and 4 RED, and the
advisory says RED. Then the simulator is paused (SIGSTOP, as a loaded machine pauses it in
lockstep) and the operator asks for light 1 GREEN: the SCM commands it, but no advisory may
say GREEN while the simulator still shows RED, whatever its state's age. Once the simulator
runs again and shows GREEN, the advisory follows. Args: ROOT BUILD PORT."""

from __future__ import annotations

import math
import os
import signal
import tempfile
import threading
import time
from pathlib import Path

from harness import Client, LightWatch, Server, add_user, check, start_sim, wait_for

from autodrive.core import lcmtypes, v2x_auth, v2x_ca
from autodrive import maps
from autodrive.core.channels import channel


def test_advisory_never_ahead_of_sim_light(
    root: Path, build_dir: Path, lcm_port: int, lcm_url: str
) -> None:
    root, build, port = str(root), str(build_dir), lcm_port
    url = lcm_url
    T = lcmtypes.load(build)
    S = T.traffic_light_state_t
    lc = lcmtypes.bus(url)
    feed_lc = lcmtypes.bus(url)
    advisories: list[tuple[float, int, int]] = []  # (wall time received [s], light id, state)
    lc.subscribe(
        channel("V2I", "NIGEL1"),
        lambda _c, d: advisories.append(
            (time.time(), (a := T.v2i_advisory_t.decode(d)).light_id, a.light_state)
        ),
    )
    watch = LightWatch(lc, T)  # also pumps lc, so the advisories above arrive

    m = maps.load("tiny_town")
    route = m.route("north_to_lot")
    light1 = next(t for t in m.lights() if t.id == 1)
    stop_c = m.stop_line(light1.stop_line).centre_m
    s_stop = min(
        (s * 0.01 for s in range(int(route.length_m * 100))),
        key=lambda s: math.dist((route.pose_at(s).x_m, route.pose_at(s).y_m), stop_c),
    )
    here = route.pose_at(s_stop - 0.5)  # the car stands 0.5 m before light 1's stop line
    feeding = threading.Event()

    # NIGEL1's V2V signed by its certificate on the bus's clock (the sim's, from its light
    # states), as its runtime signs it in HIL: the SCM takes a car's route from that car only
    car_signer, bus_clock = (
        v2x_auth.MessageSigner(v2x_ca.load_identity("NIGEL1")),
        v2x_auth.BusClock(),
    )
    feed_lc.subscribe(
        channel("TRAFFIC_LIGHT_STATE"),
        lambda _c, d: bus_clock.heard(T.traffic_light_state_t.decode(d).utime),
    )

    def feed() -> None:
        """NIGEL1's EKF pose at 20 Hz and its route on V2V at 2 Hz, on the wall clock."""
        n = 0
        while not feeding.is_set():
            while feed_lc.handle_timeout(0) > 0:  # the light states heard so far: the clock
                pass
            o = T.odometry_t()
            o.utime, o.vehicle, o.frame_id = int(time.time() * 1e6), "NIGEL1", "map"
            o.x_m, o.y_m, o.yaw_rad, o.vx_m_s = here.x_m, here.y_m, here.yaw_rad, 0.0
            feed_lc.publish(channel("POSE_MAP", "NIGEL1"), o.encode())
            if n % 10 == 0:
                v = T.v2v_state_t()
                v.utime, v.vehicle, v.route = o.utime, "NIGEL1", "north_to_lot"
                v.x_m, v.y_m, v.yaw_rad = here.x_m, here.y_m, here.yaw_rad
                car_signer.sign(channel("V2V"), v, bus_clock.now_us())
                feed_lc.publish(channel("V2V"), v.encode())
            n += 1
            time.sleep(0.05)

    def advised(since: float) -> list[int]:
        return [st for t, i, st in list(advisories) if t >= since and i == 1]

    with tempfile.TemporaryDirectory(prefix="scm-adv-") as tmp:
        db = f"sqlite:///{tmp}/scm.sqlite"
        add_user(db, "op1", "operator", "operator-pass")
        sim = start_sim(build, url, tmp)
        threading.Thread(target=feed, daemon=True).start()
        srv = Server(db, url, build, "NIGEL1")
        paused = False
        try:
            wait_for(
                lambda: watch.latest(1) is not None, 30, "the simulator publishes light states"
            )
            op = Client(srv.url)
            op.login("op1", "operator-pass")
            code, body = op.call("PUT", "/api/junctions/x/mode", {"mode": "manual"})
            check(code == 200, f"junction x manual: {code} {body}")
            for light in (1, 2, 4):
                code, body = op.call("PUT", f"/api/lights/{light}/state", {"state": "RED"})
                check(code == 200, f"light {light} RED: {code} {body}")
            wait_for(lambda: all(watch.latest(i) == S.RED for i in (1, 2, 4)), 15,
                     "lights 1, 2 and 4 RED in the simulator")  # fmt: skip
            t_red = time.time()
            wait_for(lambda: S.RED in advised(t_red), 5, "NIGEL1's advisory names light 1 RED")

            os.kill(sim.pid, signal.SIGSTOP)  # the simulator stands still: its states stop coming
            paused = True
            t_pause = time.time()
            code, body = op.call("PUT", "/api/lights/1/state", {"state": "GREEN"})
            check(
                code == 200, f"light 1 GREEN asked of the SCM while the simulator is paused: {body}"
            )

            def scm_state() -> str:
                return str(
                    next(x for x in op.call("GET", "/api/lights")[1] if x["id"] == 1)["state"]
                )

            wait_for(
                lambda: scm_state() == "GREEN", 10, "the SCM's own light 1 is GREEN (commanded)"
            )
            t_own = time.time()
            time.sleep(2.0)  # four times the SCM's old 0.5 s staleness of the simulator's state
            during = advised(t_pause)
            check(watch.latest(1) == S.RED, "the paused simulator still shows light 1 RED")
            check(len(during) >= 15, f"advisories kept coming during the pause: {len(during)}")
            greens = [t - t_own for t, i, st in list(advisories) if t >= t_pause and st == S.GREEN]
            check(
                not greens,
                f"no advisory said GREEN while the simulator showed RED ({len(during)} advisories, "
                f"{len(greens)} GREEN"
                + (
                    f", the first {greens[0]:+.2f} s after the SCM's own light turned GREEN)"
                    if greens
                    else ")"
                ),
            )

            os.kill(sim.pid, signal.SIGCONT)
            paused = False
            t_cont = time.time()
            wait_for(lambda: watch.first_after(1, S.GREEN, t_cont) is not None, 10,
                     "the simulator shows light 1 GREEN once it runs again")  # fmt: skip
            t_sim_green = watch.first_after(1, S.GREEN, t_cont)
            wait_for(lambda: S.GREEN in advised(t_cont), 5, "then the advisory says GREEN")
            first_green = min(t for t, i, st in advisories if t >= t_cont and st == S.GREEN)
            check(
                t_sim_green is not None and first_green >= t_sim_green - 0.05,
                f"the advisory's GREEN came {first_green - (t_sim_green or 0):+.3f} s after the "
                "simulator's (received here)",
            )
        finally:
            if paused:
                os.kill(sim.pid, signal.SIGCONT)
            feeding.set()
            rc = srv.stop()
            sim.terminate()
            sim.wait(timeout=30)
            watch.stop()
        check(rc == 0, f"autodrive-scm stopped cleanly on SIGTERM (rc {rc})")
    print("OK")
