"""V2V in HIL: the simulator with two cars on Tiny Town, the unchanged autodrive-runtime on each
car's ptys (clock sim, each told where it was placed), on real LCM. Each runtime broadcasts
v2v_state_t on V2V at 20 Hz of sim time from its EKF map pose with its route intent; each sees
the other as a fresh peer; when one runtime stops, the other drops its stale state and says so.
Args: ROOT BUILD PORT."""
import os
import pathlib
import select
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "python"))
from autodrive.core import v2x_ca  # noqa: E402
from autodrive.core import lcmtypes  # noqa: E402
from autodrive.core.channels import channel  # noqa: E402
from autodrive.hil.city import hil  # noqa: E402
from autodrive.core.proc import ProcessGroup, stop, wait_for_path  # noqa: E402


def test_v2v_between_two_runtimes(
    root: pathlib.Path, build_dir: pathlib.Path, lcm_port: int, lcm_url: str
) -> None:
    build, port = build_dir, lcm_port

    URL = lcm_url
    ROUTES = ["loop_ccw", "loop_cw"]
    types = lcmtypes.load(build)

    def log(msg):
        print(f"[v2v-hil] {msg}", flush=True)

    def listen(lc, seconds):
        t0 = time.monotonic()
        while time.monotonic() - t0 < seconds:
            if select.select([lc.fileno()], [], [], 0.1)[0]:
                lc.handle()

    with tempfile.TemporaryDirectory(prefix="city-v2v-") as tmp:
        out, run_dir = pathlib.Path(tmp), pathlib.Path(tmp) / "run"
        run_dir.mkdir()
        os.environ["AUTODRIVE_KEY_DIR"] = str(out / "keys")  # the test's own car keys
        v2x_ca.ensure_run_keys(["NIGEL1", "NIGEL2"], log)  # and the V2V certificates
        procs = ProcessGroup(log)
        try:
            sim = [
                build / "bin" / "autodrive-sim",
                "--map",
                "tiny_town",
                "--cars",
                "2",
                "--rtf",
                "1",
            ]
            sim += ["--no-lidar", "--run-dir", run_dir, "--lcm-url", URL, "--duration", "120"]
            procs.start("autodrive-sim", sim, out / "sim.log")
            wait_for_path(run_dir / "nigel2-nano", 60, procs)
            starts = hil.start_poses(build, URL, 2)
            log(f"start poses {starts}")
            lc = lcmtypes.bus(URL)
            got = {}  # vehicle -> list of states
            truth = {}  # vehicle -> last ground truth (x, y)

            def on_v2v(_ch, data):
                m = types.v2v_state_t.decode(data)
                got.setdefault(m.vehicle, []).append(m)

            def on_truth(_ch, data):
                m = types.ground_truth_t.decode(data)
                truth[m.vehicle] = (m.position_m[0], m.position_m[1])

            lc.subscribe(channel("V2V"), on_v2v)
            for v in ("NIGEL1", "NIGEL2"):
                lc.subscribe(channel("GROUND_TRUTH", v), on_truth)
            runtimes = []
            for i in (1, 2):
                cfg = hil.runtime_config(out, run_dir, URL, i, starts[i - 1], "")
                argv = [
                    build / "bin" / "autodrive-runtime",
                    "--config",
                    cfg,
                    "--route",
                    ROUTES[i - 1],
                ]
                runtimes.append(procs.start(f"runtime{i}", argv, out / f"runtime{i}.log"))
            # Wait until both broadcast, then measure 6 s of wall time.
            t0 = time.monotonic()
            while len(got) < 2 and time.monotonic() - t0 < 90:
                procs.check()
                listen(lc, 0.5)
            assert set(got) == {"NIGEL1", "NIGEL2"}, f"V2V heard only from {sorted(got)}"
            got.clear()
            listen(lc, 6.0)
            for i, v in enumerate(("NIGEL1", "NIGEL2")):
                states = got[v]
                span_s = (states[-1].utime - states[0].utime) * 1e-6
                rate_hz = (len(states) - 1) / span_s
                seqs = [s.seq for s in states]
                x, y = states[-1].x_m, states[-1].y_m
                tx, ty = truth[v]
                err_m = ((x - tx) ** 2 + (y - ty) ** 2) ** 0.5
                log(
                    f"{v}: {len(states)} states over {span_s:.2f} s of sim time = {rate_hz:.1f} Hz, "
                    f"route {states[-1].route!r}, pose error {err_m * 100:.1f} cm"
                )
                assert 17.0 <= rate_hz <= 23.0, f"{v} broadcasts at {rate_hz:.1f} Hz, not 20"
                assert seqs == sorted(seqs) and len(set(seqs)) == len(
                    seqs
                ), f"{v}: seq not increasing"
                assert states[-1].route == ROUTES[i], f"{v}: route {states[-1].route!r}"
                assert states[-1].route_s_m < 0
                assert err_m < 0.05, f"{v}: V2V pose {err_m:.3f} m from ground truth"
            # Each runtime's status says it sees the other.
            time.sleep(6.0)
            for i, other in ((1, "NIGEL2"), (2, "NIGEL1")):
                text = (out / f"runtime{i}.log").read_text()
                assert (
                    f"1 fresh peer(s) ({other})" in text
                ), f"runtime{i} never saw {other}:\n{text}"
            # Stop runtime 2: runtime 1 must drop its state as stale and say so.
            assert stop(runtimes[1], "runtime2", log) == 0
            deadline = time.monotonic() + 30
            while time.monotonic() < deadline:
                text = (out / "runtime1.log").read_text()
                if "0 fresh peer(s), 1 stale state(s) dropped" in text:
                    break
                time.sleep(0.5)
            else:
                raise AssertionError(f"runtime1 did not drop NIGEL2's stale state:\n{text}")
            log("runtime1 dropped NIGEL2's stale state and said so")
        finally:
            procs.stop_all()
    print("v2v hil ok")
