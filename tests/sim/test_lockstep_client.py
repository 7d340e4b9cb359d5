"""autodrive-sim --lockstep-client on a real pty and real UDP LCM (port 7753): real time until
the client first writes; then never more than 40 ms of sim time past the client's last bytes
(a silent client holds the sim); a client that writes keeps it going; after 2 s of wall time
without bytes the sim gives the client up and runs on, saying so."""
import os
import pathlib
import select
import subprocess
import tempfile
import time

from autodrive.core import lcmtypes
from autodrive.core.channels import channel


def test_lockstep_client_holds_the_sim(
    root: pathlib.Path, build_dir: pathlib.Path, lcm_port: int, lcm_url: str
) -> None:
    build, port = build_dir, lcm_port
    types = lcmtypes.load(build)

    url = lcm_url
    lc = lcmtypes.bus(url)
    clock = {"us": None}
    lc.subscribe(
        channel("SIM_CLOCK"), lambda _c, d: clock.update(us=types.sim_clock_t.decode(d).utime)
    )

    def pump(wall_s):
        """Handles LCM for wall_s seconds; returns the latest sim time [s] seen."""
        end = time.time() + wall_s
        while time.time() < end:
            if select.select([lc.fileno()], [], [], 0.02)[0]:
                lc.handle()
        return clock["us"] * 1e-6 if clock["us"] is not None else None

    with tempfile.TemporaryDirectory(prefix="sim-lockstep-") as run_dir:
        sim = subprocess.Popen(
            [
                str(build / "bin" / "autodrive-sim"),
                "--lockstep-client",
                "--no-lidar",
                "--duration",
                "600",
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
            pty = pathlib.Path(run_dir) / "nigel1-nano"
            for _ in range(300):
                if pty.exists():
                    break
                time.sleep(0.05)
            assert pty.exists(), "the Nano pty did not appear"
            t0 = pump(1.0)
            t1 = pump(1.0)
            assert t0 is not None and t1 is not None, "no SIM_CLOCK"
            # Before any client bytes: paced at real time (a loaded machine may run slower).
            assert 0.2 <= t1 - t0 <= 1.5, f"before the client: {t1 - t0:.3f} s sim in 1 s wall"
            fd = os.open(str(pty), os.O_RDWR | os.O_NOCTTY)
            os.write(fd, b"\x00")
            t_write = pump(0.2)
            t_held = pump(1.0)
            # One byte buys at most 40 ms; the sim then waits for the silent client.
            assert (
                t_held - t_write <= 0.06
            ), f"a silent client did not hold the sim: +{t_held - t_write:.3f} s"
            end = time.time() + 1.0
            while time.time() < end:  # a client writing every 5 ms of wall time
                os.write(fd, b"\x00")
                pump(0.005)
            t_fed = pump(0.05)
            assert (
                t_fed - t_held >= 0.2
            ), f"a writing client did not move the sim: +{t_fed - t_held:.3f} s"
            t_gone = pump(4.0)  # silent again: after 2 s wall the sim runs on without it
            assert (
                t_gone - t_fed >= 1.0
            ), f"the sim waited for a gone client: +{t_gone - t_fed:.3f} s"
            os.close(fd)
        finally:
            sim.terminate()
            err = sim.communicate(timeout=10)[1]
        assert (
            "no bytes from the client" in err
        ), f"no message about the silent client:\n{err[-2000:]}"
        print(
            f"lockstep client ok: real time {t1 - t0:.3f} s/s, held +{t_held - t_write:.3f} s, "
            f"fed +{t_fed - t_held:.3f} s, released +{t_gone - t_fed:.3f} s"
        )
