"""Ghost cars on V2V in HIL, measured by the city driver's own per-peer account: one car
(NIGEL1) on Tiny Town's city_east with its unchanged autodrive-runtime (Eye stand-in, V2V on),
its autodrive-city-driver, the advisory stand-in and autodrive-sim in lockstep, on real LCM.
For each V2V state of NIGEL1 this test announces ghost cars 0.3 m ahead of it:
  - forged (every phase): unsigned as NIGEL9; as NIGEL2 signed by NIGEL1's own certificate; as
    NIGEL2 and NIGEL9 with certificates of another authority;
  - planted (from FORGED_ONLY_S of sim time on): NIGEL5, signed by a valid car certificate of
    the testbed's CA for its own name (a ghost no check can refuse), and its states replayed
    1 s of sim time later.
The driver's account must charge the forged ghosts 0 s in its peer table and 0 s of held time,
and the planted one more than 1 s of held time: the measurement catches a ghost that gets in.
Args: ROOT BUILD PORT (ctest: --lcm-port)."""

from __future__ import annotations

import math
import os
import pathlib
import select
import sys
import tempfile
import time
from typing import Any

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "python"))
from autodrive.core import lcmtypes, v2x_auth, v2x_ca  # noqa: E402
from autodrive.core.channels import channel  # noqa: E402
from autodrive.core.proc import ProcessGroup, wait_for_path  # noqa: E402
from autodrive.hil.city import hil, peer_account, scoring  # noqa: E402
from autodrive.maps.loader import MAPS_DIR  # noqa: E402

CAR, ROUTE = "NIGEL1", "city_east"
AHEAD_M = 0.3  # where the ghosts stand, along the car's heading from its base_link [m]
FORGED_ONLY_S = 15.0  # sim time with forged ghosts only [s]
PLANTED_S = 10.0  # then sim time with the planted ghost too [s]
REPLAY_LATE_US = 1_000_000  # the planted ghost's states replayed this late [us, sim]
WALL_LIMIT_S = 900.0  # only a hang guard: the test waits on sim time


class Ghosts:
    """The ghost cars, published on each of the car's own V2V states."""

    def __init__(self, types: Any, lc: Any, key_dir: pathlib.Path, rogue: pathlib.Path) -> None:
        self.types, self.lc = types, lc
        own = v2x_auth.MessageSigner(v2x_ca.load_identity(CAR, key_dir))
        self.forged: list[tuple[str, v2x_auth.MessageSigner | None]] = [
            ("NIGEL9", None),
            ("NIGEL2", own),
            ("NIGEL2", v2x_auth.MessageSigner(v2x_ca.load_identity("NIGEL2", rogue))),
            ("NIGEL9", v2x_auth.MessageSigner(v2x_ca.load_identity("NIGEL9", rogue))),
        ]
        self.planted = v2x_auth.MessageSigner(v2x_ca.load_identity("NIGEL5", key_dir))
        self.replays: list[tuple[int, bytes]] = []  # (due [us, sim], the planted state's bytes)
        self.sent = 0

    def ghost(self, own: Any, name: str, signer: v2x_auth.MessageSigner | None) -> Any:
        g = self.types.v2v_state_t.decode(own.encode())
        g.vehicle, g.speed_m_s, g.auth, g.auth_len = name, 0.0, b"", 0
        g.x_m += AHEAD_M * math.cos(own.yaw_rad)
        g.y_m += AHEAD_M * math.sin(own.yaw_rad)
        if signer is not None:
            signer.sign(channel("V2V"), g, own.utime)
        return g

    def on_own_state(self, own: Any, planted: bool) -> None:
        for name, signer in self.forged:
            self.publish(self.ghost(own, name, signer).encode())
        if planted:
            data = self.ghost(own, "NIGEL5", self.planted).encode()
            self.publish(data)
            self.replays.append((own.utime + REPLAY_LATE_US, data))
        while self.replays and self.replays[0][0] <= own.utime:
            self.publish(self.replays.pop(0)[1])

    def publish(self, data: bytes) -> None:
        self.lc.publish(channel("V2V"), data)
        self.sent += 1


def test_ghost_cars_cost_nothing_and_a_planted_one_is_caught(
    build_dir: pathlib.Path, lcm_url: str
) -> None:
    build, url = build_dir, lcm_url
    types = lcmtypes.load(build)

    def log(msg: str) -> None:
        print(f"[ghost-car] {msg}", flush=True)

    with tempfile.TemporaryDirectory(prefix="ghost-car-") as tmp:
        out, run_dir = pathlib.Path(tmp), pathlib.Path(tmp) / "run"
        run_dir.mkdir()
        key_dir = out / "keys"
        os.environ["AUTODRIVE_KEY_DIR"] = str(key_dir)
        v2x_ca.ensure_run_keys([CAR], log)
        v2x_ca.Authority(key_dir).issue("NIGEL5", "car", 1)  # valid, but no such car runs
        rogue = out / "rogue"  # another authority's certificates for real and unknown names
        v2x_ca.Authority(rogue).init()
        for name in ("NIGEL2", "NIGEL9"):
            v2x_ca.Authority(rogue).issue(name, "car", 1)
        facts = scoring.MapFacts.load(MAPS_DIR / "tiny_town.json")
        x, y, yaw = facts.lane_point("s3_e_w", back_from_end_m=0.95)
        procs = ProcessGroup(log)
        lc = lcmtypes.bus(url)
        ghosts = Ghosts(types, lc, key_dir, rogue)
        truth: dict[str, float] = {}
        moved = {"start": None, "at_planted": None}

        def on_truth(_ch: str, data: bytes) -> None:
            m = types.ground_truth_t.decode(data)
            truth.update(t=m.utime * 1e-6, x=m.position_m[0], y=m.position_m[1])

        def on_v2v(_ch: str, data: bytes) -> None:
            m = types.v2v_state_t.decode(data)
            if m.vehicle == CAR and v2x_auth.auth_of(m):  # the car's own (runtime-signed) state
                ghosts.on_own_state(m, planted=m.utime * 1e-6 >= FORGED_ONLY_S)

        lc.subscribe(channel("GROUND_TRUTH", CAR), on_truth)
        lc.subscribe(channel("V2V"), on_v2v)

        def run_until(sim_s: float) -> None:
            t0 = time.monotonic()
            while truth.get("t", 0.0) < sim_s:
                assert time.monotonic() - t0 < WALL_LIMIT_S, f"sim time stuck at {truth}"
                procs.check()
                if select.select([lc.fileno()], [], [], 0.05)[0]:
                    lc.handle()

        try:
            sim = [build / "bin" / "autodrive-sim", "--map", "tiny_town", "--cars", 1]
            sim += ["--start", f"{x:.4f},{y:.4f},{math.degrees(yaw):.3f}"]
            sim += ["--lockstep-client", "--run-dir", run_dir, "--lcm-url", url]
            sim += ["--duration", FORGED_ONLY_S + PLANTED_S + 30, "--no-late-obstacles"]
            procs.start("autodrive-sim", sim, out / "sim.log")
            wait_for_path(run_dir / "nigel1-nano", 60, procs)
            poses = hil.start_poses(build, url, 1)
            py = [sys.executable, "-m"]
            common = ["--vehicles", CAR, "--lcm-url", url, "--build", build]
            procs.start("eye-standin", [*py, "autodrive.hil.city.eye_standin", *common],
                        out / "eye.log")  # fmt: skip
            adv = [*py, "autodrive.hil.city.advisory", "--map", "tiny_town", *common]
            procs.start("advisory", [*adv, "--routes", ROUTE], out / "advisory.log")
            cfg = hil.runtime_config(out, run_dir, url, 1, poses[0], ROUTE)
            procs.start("runtime", [build / "bin" / "autodrive-runtime", "--config", cfg],
                        out / "runtime.log")  # fmt: skip
            drv = [build / "bin" / "autodrive-city-driver", "--map", MAPS_DIR / "tiny_town.json"]
            drv += ["--route", ROUTE, "--vehicle", CAR, "--lcm-url", url, "--clock", "sim"]
            drv += ["--no-lidar"]
            procs.start("city-driver", drv, out / "driver.log")
            run_until(2.0)
            moved["start"] = (truth["x"], truth["y"])
            run_until(FORGED_ONLY_S)
            moved["at_planted"] = (truth["x"], truth["y"])
            run_until(FORGED_ONLY_S + PLANTED_S)
        finally:
            procs.stop_all()
        text = (out / "driver.log").read_text()
        records = peer_account.read(out / "driver.log")
        log(f"{ghosts.sent} ghost states sent; account: {records}")
        log("refused: " + next((ln for ln in text.splitlines() if "refused V2X" in ln), "none"))
        planted_serial = v2x_ca.load_identity("NIGEL5", key_dir).cert.serial
        forged = peer_account.ghosts(records, {"NIGEL5": planted_serial})
        assert forged == [], f"forged ghosts got into the peer table: {forged}"
        planted = [r for r in records if r.name == "NIGEL5"]
        assert planted and planted[0].held_s > 1.0, f"the planted ghost was not caught: {records}"
        # the forged ghosts did not hold the car: it drove while only they were there
        assert moved["start"] and moved["at_planted"]
        assert math.dist(moved["start"], moved["at_planted"]) > 0.2, moved
        assert "stale" in text or "replayed" in text, "the planted ghost's replays got no refusal"
    print("ghost car hil ok")
