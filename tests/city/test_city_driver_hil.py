"""The smart-city behaviour layer in HIL: autodrive-sim (Tiny Town, lockstep with the runtime),
the unchanged autodrive-runtime on its ptys (its EKF fed by the Eye stand-in,
autodrive.hil.city.eye_standin), autodrive-city-driver on Tiny Town's loop city_east (through light
3 and the stop sign), and the test's own V2I advisory publisher (autodrive.hil.city.advisory),
all on real LCM. Judged from the simulator's ground truth and light states:
1. light 3 held GREEN, the advisory stopped once the car drives (stale): the car stops with its
   front before the stop line anyway (overshoot <= 3 cm);
2. the advisory back, light 3 held RED: the car stays; then GREEN: it goes on across the line;
3. the stop sign: a standstill of at least 1 s before it, then on;
4. a box steps onto the lane ahead (autodrive-sim --late-box, 0.9 m ahead of the car) and leaves
   again 12 s later: the car, seeing it only with its LIDAR, stands with its front the driver's
   obstacle margin before it (within 3 cm), never touches it, and goes on once it is gone.
(Stopping on RED from cruise is city.gap_keeping's leader; this order saves a lap.)
Args: ROOT BUILD PORT."""
import math
import os
import pathlib
import re
import select
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "python"))
from autodrive.core import v2x_auth, v2x_ca  # noqa: E402
from autodrive.core import lcmtypes  # noqa: E402
from autodrive.core.channels import channel  # noqa: E402
from autodrive.hil.city import hil, scoring  # noqa: E402
from autodrive.maps.loader import MAPS_DIR  # noqa: E402
from autodrive.core.proc import ProcessGroup, stop, wait_for_path  # noqa: E402


def test_city_driver_obeys(
    root: pathlib.Path, build_dir: pathlib.Path, lcm_port: int, lcm_url: str
) -> None:
    build, port = build_dir, lcm_port

    URL = lcm_url
    MAP = MAPS_DIR / "tiny_town.json"
    LIGHT = 3
    ROUTE = "city_east"  # north through light 3 and the stop sign, round the east half
    SIM_LIMIT_S = 400.0
    # the box: on lane n2_w_e (y 2.86 m, heading east), after the stop sign; half sizes [m]
    # it appears 0.9 m ahead (4.5 s of driving) and stays 12 s: under ASan the driver runs late
    # against the lockstep sim, and a 6 s stay once ran out before the car got there (CI, 16:00 UTC)
    BOX_X, BOX_Y, BOX_HALF_M, BOX_NEAR_M, BOX_STAY_S = 2.2, 2.86, 0.06, 0.9, 12.0
    types = lcmtypes.load(build)

    def log(msg):
        print(f"[city-hil] {msg}", flush=True)

    with tempfile.TemporaryDirectory(prefix="city-driver-") as tmp:
        out, run_dir = pathlib.Path(tmp), pathlib.Path(tmp) / "run"
        run_dir.mkdir()
        os.environ["AUTODRIVE_KEY_DIR"] = str(out / "keys")
        v2x_ca.ensure_run_keys(["NIGEL1"], log)  # and the V2I certificates
        facts = scoring.MapFacts.load(MAP)
        line = facts.stop_for_light(LIGHT)
        sign = facts.stop_sign_points()[0]
        # Start 1.5 m before the end of the lane that leads into the T-junction before light 3.
        start = facts.lane_point("s3_e_w", back_from_end_m=1.2)
        procs = ProcessGroup(log)
        lc = lcmtypes.bus(URL)
        truth = {}
        samples = []  # every ground-truth sample: (t [s], x [m], y [m], yaw [rad])
        lights = {}

        track = open(out / "truth.csv", "w")

        def on_truth(_ch, data):
            m = types.ground_truth_t.decode(data)
            track.write(
                f"{m.utime * 1e-6:.2f},{m.position_m[0]:.4f},{m.position_m[1]:.4f},{m.yaw_rad:.3f}\n"
            )
            v = m.linear_velocity_m_s[0]
            truth.update(t=m.utime * 1e-6, x=m.position_m[0], y=m.position_m[1], yaw=m.yaw_rad, v=v)
            samples.append((m.utime * 1e-6, m.position_m[0], m.position_m[1], m.yaw_rad))
            if m.in_collision:
                truth["collisions"] = truth.get("collisions", 0) + 1

        # light commands as the SCM would send them: signed, on the bus's (the sim's) clock
        scm_signer, bus_clock = (
            v2x_auth.MessageSigner(v2x_ca.load_identity("SCM")),
            v2x_auth.BusClock(),
        )

        def on_light(_ch, data):
            m = types.traffic_light_state_t.decode(data)
            lights[m.light_id] = m.state
            bus_clock.heard(m.utime)

        lc.subscribe(channel("GROUND_TRUTH", "NIGEL1"), on_truth)
        lc.subscribe(channel("TRAFFIC_LIGHT_STATE"), on_light)

        def command_light(state):
            c = types.traffic_light_command_t()
            c.utime, c.light_id, c.state, c.duration_s = bus_clock.now_us(), LIGHT, state, 0.0
            scm_signer.sign(channel("TRAFFIC_LIGHT_COMMAND"), c, bus_clock.now_us())
            lc.publish(channel("TRAFFIC_LIGHT_COMMAND"), c.encode())

        def spin(seconds):
            t0 = time.monotonic()
            while time.monotonic() - t0 < seconds:
                if select.select([lc.fileno()], [], [], 0.05)[0]:
                    lc.handle()

        # Judged on sim time: the lockstep sim runs as fast as the slowest of the loop, so a busy
        # host makes a run slower, never different. Only a sim clock that stops is an error.
        STALL_WALL_S = 120.0  # a hang backstop, not a deadline: no sim time at all for this long

        def wait_for(what, cond, sim_s=120.0):
            t_start, seen_t, seen_wall = truth.get("t", 0.0), None, time.monotonic()
            while True:
                procs.check()
                spin(0.1)
                now = truth.get("t")
                if now != seen_t:
                    seen_t, seen_wall = now, time.monotonic()
                elif time.monotonic() - seen_wall > STALL_WALL_S:
                    raise AssertionError(
                        f"{what}: the sim clock stopped for {STALL_WALL_S} s; {truth}"
                    )
                if truth and cond():
                    return
                if truth and (truth["t"] > t_start + sim_s or truth["t"] > SIM_LIMIT_S):
                    raise AssertionError(f"{what}: not within {sim_s} s of sim time; {truth}")

        def set_light(state, what):
            """Commands light 3 to hold state until it shows it: the simulator refuses a GREEN while
            a conflicting light is green on its program, so one command may not do. The first
            command goes out even when the program shows state already, or it would move on."""
            sent_t = [None]  # sim time of the last command [s]

            def shown():
                resend = sent_t[0] is None or truth["t"] - sent_t[0] > 0.5
                if resend and (sent_t[0] is None or lights.get(LIGHT) != state):
                    command_light(state)
                    sent_t[0] = truth["t"]
                return lights.get(LIGHT) == state

            wait_for(what, shown, 30.0)

        def past(stop_point):
            return scoring.front_past_m(truth["x"], truth["y"], truth["yaw"], stop_point)

        STILL_M = 0.003  # a standing car's body moves less than this [m]

        def stopped_at(stop_point, hold_s):
            """Waits until the car has stood within 0.25 m before stop_point for hold_s of sim time;
            returns how far its front stood past it [m]. Standing is judged by where the car is, not
            by its body's speed: that speed wobbles above 1 cm/s as the body settles after braking,
            and once hid a 1.3 s stop. Every ground-truth sample is judged, not only those current
            when the test looks: a lockstep sim ran a whole 1.2 s stop between two looks (CI)."""
            anchor = [None]  # (t [s], x [m], y [m]) where the standstill began
            seen, stood_past = [len(samples)], [None]

            def stood():
                while seen[0] < len(samples):
                    t, x, y, yaw = samples[seen[0]]
                    seen[0] += 1
                    gap = scoring.front_past_m(x, y, yaw, stop_point)
                    if not -0.25 < gap < 0.1:
                        anchor[0] = None
                        continue
                    if anchor[0] is None or math.dist(anchor[0][1:], (x, y)) > STILL_M:
                        anchor[0] = (t, x, y)
                    if t - anchor[0][0] >= hold_s:
                        stood_past[0] = gap
                        return True
                return False

            wait_for(f"stood {hold_s} s at {stop_point.name}", stood)
            return stood_past[0]

        try:
            sim = [build / "bin" / "autodrive-sim", "--map", "tiny_town", "--cars", "1"]
            sim += ["--start", f"{start[0]:.4f},{start[1]:.4f},{math.degrees(start[2]):.3f}"]
            sim += ["--lockstep-client", "--run-dir", run_dir, "--lcm-url", URL]
            # the map's late box appears in the crossroads when a car comes near it; the city driver
            # does not avoid obstacles (the smart-city mission leaves them out too)
            sim += ["--duration", SIM_LIMIT_S + 20, "--no-late-obstacles"]
            sim += ["--late-box", f"{BOX_X},{BOX_Y},0,{BOX_HALF_M},{BOX_HALF_M},{BOX_NEAR_M}"]
            sim += ["--late-box-stay", BOX_STAY_S]
            procs.start("autodrive-sim", sim, out / "sim.log")
            wait_for_path(run_dir / "nigel1-nano", 60, procs)
            pose0 = hil.start_poses(build, URL, 1)[0]
            cfg = hil.runtime_config(out, run_dir, URL, 1, pose0, ROUTE, lidar=True)
            procs.start(
                "runtime",
                [build / "bin" / "autodrive-runtime", "--config", cfg],
                out / "runtime.log",
            )
            eye = [
                sys.executable,
                "-m",
                "autodrive.hil.city.eye_standin",
                "--vehicles",
                "NIGEL1",
                "--lcm-url",
                URL,
                "--build",
                build,
            ]
            procs.start("eye-standin", eye, out / "eye.log")
            adv = [
                sys.executable,
                "-m",
                "autodrive.hil.city.advisory",
                "--map",
                "tiny_town",
                "--vehicles",
                "NIGEL1",
                "--routes",
                ROUTE,
                "--lcm-url",
                URL,
                "--build",
                build,
            ]
            advisory = procs.start("advisory", adv, out / "advisory.log")
            spin(1.0)
            set_light(3, "light 3 GREEN")  # held
            drv = [
                build / "bin" / "autodrive-city-driver",
                "--map",
                MAP,
                "--route",
                ROUTE,
                "--lcm-url",
                URL,
                "--clock",  # the advisory's age in sim time, as the runtime's
                "sim",
            ]
            procs.start("city-driver", drv, out / "driver.log")
            # 1. stale advisory: light 3 stays GREEN in the sim, the car stops at it anyway
            wait_for("driving", lambda: truth["v"] > 0.1)
            assert stop(advisory, "advisory", log) == 0
            over_stale = stopped_at(line, 2.0)
            log(
                f"1. stale advisory: stood {-over_stale * 100:.1f} cm before the line, light "
                f"{lights[LIGHT]} (3 = GREEN)"
            )
            assert lights[LIGHT] == 3, "the light was not green: the test proves nothing"
            assert over_stale <= 0.03
            text = (out / "driver.log").read_text()
            assert "stale advisory: red light 3" in text, text[-2000:]
            # 2. the advisory back, RED: the car stays; GREEN: it goes
            set_light(1, "light 3 RED")
            procs.start("advisory2", adv, out / "advisory2.log")
            t_red, at_red = truth["t"], (truth["x"], truth["y"])

            def moved_m():
                return math.dist(at_red, (truth["x"], truth["y"]))

            wait_for("2 s of red", lambda: truth["t"] > t_red + 2.0 or moved_m() > 0.01)
            assert moved_m() <= 0.01 and past(line) < 0, f"the car moved on red: {truth}"
            set_light(3, "light 3 GREEN again")
            wait_for("across the line on green", lambda: past(line) > 0.3)
            log("2. red: stayed; green: crossed the stop line")
            # 3. stop sign: a full stop of >= 1 s, then on
            over_sign = stopped_at(sign, 1.0)
            wait_for("on after the stop sign", lambda: past(sign) > 0.3)
            log(f"3. stop sign: stood >= 1 s, {-over_sign * 100:.1f} cm before it, then went on")
            assert over_sign <= 0.03
            # 4. the box on the lane: stand the obstacle margin before it, go on when it is gone
            rules = re.search(
                r"rules: min_gap_m=\S+ obstacle_margin_m=([0-9.]+)",
                (out / "driver.log").read_text(),
            )
            assert rules, "the driver's log has no rules line"
            margin = float(rules.group(1))

            def box_gap():  # the box's west face less the car's front, along the lane (east) [m]
                front = truth["x"] + scoring.front_offset_m() * math.cos(truth["yaw"])
                return BOX_X - BOX_HALF_M - front

            wait_for(
                "standing before the box", lambda: abs(truth["v"]) < 0.01 and 0 < box_gap() < 0.5
            )
            gap = box_gap()
            assert "late box 1 appeared" in (out / "sim.log").read_text()
            log(
                f"4. box on the lane: stood {gap * 100:.1f} cm before it (margin {margin * 100:.0f} cm)"
            )
            assert margin - 0.03 <= gap <= margin + 0.05, f"stood {gap:.3f} m before the box"
            wait_for("on past the box once it left", lambda: truth["x"] > BOX_X + 0.3)
            assert "late box 1 left" in (out / "sim.log").read_text()
            assert truth.get("collisions", 0) == 0, "the car touched something"
            log("   the box left; the car went on")
        finally:
            procs.stop_all()
            keep = os.environ.get("CITY_TEST_KEEP")  # a folder to keep the logs in
            if keep:
                subprocess.run(["cp", "-r", str(out), keep], check=False)
            for f in ("driver.log", "runtime.log"):
                p = out / f
                if p.exists():
                    print(f"---- {f} (tail)\n" + "\n".join(p.read_text().splitlines()[-15:]))
    print("city driver hil ok")
