"""Traffic lights on real LCM (UDP multicast on loopback, port from argv): autodrive-sim on
Intersection School at real time (--rtf 1, SIM_CLOCK on) publishes TRAFFIC_LIGHT_STATE for every
light at 10 Hz; a TRAFFIC_LIGHT_COMMAND to RED is on the bus (the light's state message) within
100 ms of sim time; a command that would put two conflicting lights green is refused, the
simulator's log names both light ids, and the light stays red. Every wait is on sim time (the
simulator's SIM_CLOCK) or event order: a loaded machine only slows the run."""
import pathlib
import select
import subprocess
import tempfile
import time
from collections import Counter

from autodrive.core import lcmtypes, v2x_auth, v2x_ca
from autodrive.core.channels import channel


def test_traffic_lights_on_lcm(
    root: pathlib.Path, build_dir: pathlib.Path, lcm_port: int, lcm_url: str
) -> None:
    build, port = build_dir, lcm_port
    types = lcmtypes.load(build)
    State, Command = types.traffic_light_state_t, types.traffic_light_command_t

    url = lcm_url
    lc = lcmtypes.bus(url)
    clock = {"us": None}
    states: list[tuple[float, object]] = []  # (wall time received, message)
    lc.subscribe(
        channel("SIM_CLOCK"), lambda _c, d: clock.update(us=types.sim_clock_t.decode(d).utime)
    )
    lc.subscribe(
        channel("TRAFFIC_LIGHT_STATE"), lambda _c, d: states.append((time.time(), State.decode(d)))
    )

    def pump_until(done, guard_s: float = 120.0) -> None:  # type: ignore[no-untyped-def]
        """Until done() (event order); the wall guard only ends a hang."""
        end = time.monotonic() + guard_s
        while not done() and time.monotonic() < end:
            if select.select([lc.fileno()], [], [], 0.01)[0]:
                lc.handle()

    def pump(sim_s: float) -> None:
        """For sim_s of the simulator's time (SIM_CLOCK) from now."""
        pump_until(lambda: clock["us"] is not None)
        until_us = clock["us"] + int(sim_s * 1e6)
        pump_until(lambda: clock["us"] >= until_us)

    # signed as the SCM (the only role the simulator obeys), on the sim clock
    scm = v2x_auth.MessageSigner(v2x_ca.load_identity("SCM"))

    def command(light_id: int, state: int, duration_s: float = 0.0, signed: bool = True) -> None:
        msg = Command()
        msg.utime = clock["us"] or 0
        msg.light_id, msg.state, msg.duration_s = light_id, state, duration_s
        if signed:
            scm.sign(channel("TRAFFIC_LIGHT_COMMAND"), msg, msg.utime)
        lc.publish(channel("TRAFFIC_LIGHT_COMMAND"), msg.encode())

    with tempfile.TemporaryDirectory(prefix="world-lights-") as run_dir:
        sim = subprocess.Popen(
            [
                str(build / "bin" / "autodrive-sim"),
                "--map",
                "intersection_school",
                "--rtf",
                "1",
                "--no-pty",
                "--no-lidar",
                "--quiet",
                "--duration",
                "60",
                "--run-dir",
                run_dir,
                "--lcm-url",
                url,
            ],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            text=True,
        )
        try:
            pump(1.0)
            assert clock["us"] is not None, "no SIM_CLOCK"
            t0_us = clock["us"]
            states.clear()
            pump(2.0)
            t1_us = clock["us"]
            per_light = Counter(m.light_id for _, m in states)
            span_s = (t1_us - t0_us) * 1e-6
            print(f"{dict(per_light)} state messages in {span_s:.2f} s of sim time")
            assert sorted(per_light) == [1, 2, 3, 4], per_light
            for light, n in per_light.items():
                assert (
                    abs(n / span_s - 10.0) < 2.5
                ), f"light {light}: {n / span_s:.1f} Hz, not 10 Hz"
            # t ~ 3 s of sim time: programs have lights 1 and 3 green (offset 0), 2 and 4 red (offset 10 s)
            latest = {m.light_id: m.state for _, m in states}
            assert latest[1] == State.GREEN and latest[2] == State.RED, latest
            # a green for light 2 would conflict with light 1 (green): refused, light 2 stays red
            command(2, State.GREEN)
            pump(0.5)
            assert all(m.state == State.RED for _, m in states[-8:] if m.light_id == 2)
            # RED for light 1: its state on the bus within 100 ms of sim time
            states.clear()
            sent_us = clock["us"]
            command(1, State.RED)
            pump(0.5)
            red = [m for _, m in states if m.light_id == 1 and m.state == State.RED]
            assert red, "no RED state of light 1 after the command"
            lag_ms = (red[0].utime - sent_us) * 1e-3
            print(f"light 1 RED on the bus {lag_ms:.1f} ms of sim time after the command was sent")
            assert lag_ms <= 100.0, f"{lag_ms:.1f} ms"
            assert red[0].time_remaining_s < 0  # held until the next command
            # an unsigned GREEN for light 1 (no conflict now: all red but 3) is not obeyed
            states.clear()
            command(1, State.GREEN, signed=False)
            # 8 states of light 1 after it (0.8 s of sim time): the command was handled
            pump_until(lambda: sum(m.light_id == 1 for _, m in states) >= 8)
            ones = [m for _, m in states if m.light_id == 1]
            assert len(ones) >= 8 and all(m.state == State.RED for m in ones), "obeyed"
        finally:
            sim.terminate()
            _, err = sim.communicate(timeout=20)
        print(err.strip())
        refusal = [ln for ln in err.splitlines() if "refused" in ln]
        assert refusal, "the refusal was not logged"
        assert "light 2" in refusal[0] and "light 1" in refusal[0], refusal[0]
        dropped = [ln for ln in err.splitlines() if "TRAFFIC_LIGHT_COMMAND dropped" in ln]
        assert dropped and "unknown sender" in dropped[0] and "unsigned" in dropped[0], dropped
        assert sim.returncode == 0, sim.returncode
    print("OK")
