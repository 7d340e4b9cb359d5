"""The same smart-city episode at full speed and paced at 0.1x real time gives the same result
(issue 41: every component of the HIL loop on the simulator's clock). tools/demo --mission
smart-city twice, seed 7, Tiny Town's three cars on the real chain (autodrive-sim, three
runtimes, three city drivers on --clock sim, the Eye stand-in and the advisory stand-in, real
LCM on the test's port): once in lockstep with the runtimes (the mission's default), once with
autodrive-sim --rtf 0.1 (tools/demo --rtf 0.1). Each car's episode is the WINDOW_S of sim time
after it first moves (the programs start at different sim times of the two runs, as starting
costs wall time). The test listens to the bus and stops each run (SIGINT) when every car's
window is over, judged in sim time only; wall time is only a hang guard.

Equal: red-light and stop-sign violations, collisions and laps (exactly); each car's distance
driven in its window within TOLERANCE_M (the runs differ only in how late, in sim time, a command
reaches the simulator: up to 40 ms at full speed, ~1 ms paced). Args: ROOT BUILD PORT."""

from __future__ import annotations

import json
import math
import os
import select
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from autodrive.core import lcmtypes
from autodrive.core.channels import channel, vehicle_name

SEED = 7
CARS = 3
WINDOW_S = 3.0  # each car's episode [s of sim time after it first moves]
MOVING_M_S = 0.02  # a car moves when its true speed exceeds this [m/s]
TOLERANCE_M = 0.02  # distance driven in the window, full speed vs paced [m] (measured: <= 2 mm)
SIM_GUARD_S = 120.0  # no car moved within this much sim time: the run is broken [s]
WALL_GUARD_S = 600.0  # a hang guard only [s wall]


def episode(build: Path, out: Path, url: str, rtf: float | None) -> dict[str, object]:
    """Runs the mission until every car's window is over (sim time); returns its report with
    each car's distance driven in its window (driven_in_window_m)."""
    types = lcmtypes.load(build)
    lc = lcmtypes.bus(url)
    first: dict[str, float] = {}  # car -> sim time it first moved [s]
    last: dict[str, tuple[float, float, float]] = {}  # car -> (t, x, y) of the last sample
    driven: dict[str, float] = {}  # car -> distance in its window [m]
    sim_t = [0.0]

    def on_truth(_c: str, data: bytes) -> None:
        m = types.ground_truth_t.decode(data)
        t, x, y = m.utime * 1e-6, m.position_m[0], m.position_m[1]
        sim_t[0] = max(sim_t[0], t)
        if m.vehicle not in first and math.hypot(*m.linear_velocity_m_s[:2]) > MOVING_M_S:
            first[m.vehicle], driven[m.vehicle] = t, 0.0
        if m.vehicle in first and t <= first[m.vehicle] + WINDOW_S and m.vehicle in last:
            t0, x0, y0 = last[m.vehicle]
            if t > t0:
                driven[m.vehicle] += math.hypot(x - x0, y - y0)
        last[m.vehicle] = (t, x, y)

    for i in range(1, CARS + 1):
        lc.subscribe(channel("GROUND_TRUTH", vehicle_name(i)), on_truth)
    cmd = [sys.executable, "-m", "autodrive.hil.demo", "--mission", "smart-city", "--headless",
           "--build", str(build), "--out", str(out), "--seed", str(SEED),
           "--eye", "standin", "--advisory", "standin", "--lcm-url", url,
           "--timeout", str(WALL_GUARD_S)]  # fmt: skip
    if rtf is not None:
        cmd += ["--rtf", str(rtf)]
    env = dict(os.environ, AUTODRIVE_KEY_DIR=str(out.parent / "keys"))
    demo = subprocess.Popen(cmd, env=env)
    t_wall0 = time.time()
    try:
        while demo.poll() is None and time.time() - t_wall0 < WALL_GUARD_S:
            if select.select([lc.fileno()], [], [], 0.1)[0]:
                lc.handle()
            done = len(first) == CARS and all(last[c][0] > first[c] + WINDOW_S for c in first)
            if done or (sim_t[0] > SIM_GUARD_S and len(first) < CARS):
                break
        assert demo.poll() is None, f"the mission ended early (exit {demo.returncode})"
        demo.send_signal(signal.SIGINT)
        demo.wait(timeout=120)
    finally:
        if demo.poll() is None:
            demo.kill()
    assert len(first) == CARS, f"only {sorted(first)} moved within {SIM_GUARD_S:g} s of sim time"
    rep: dict[str, object] = json.loads((out / "report.json").read_text())
    rep["driven_in_window_m"] = dict(sorted(driven.items()))
    rep["first_moved_s"] = dict(sorted(first.items()))
    return rep


def test_same_episode_full_speed_and_paced(build_dir: Path, lcm_port: int) -> None:
    url = f"udpm://239.255.76.67:{lcm_port}?ttl=0"
    with tempfile.TemporaryDirectory(prefix="city-paced-") as tmp:
        runs = {}
        for name, rtf in (("full", None), ("paced_0.1x", 0.1)):
            t0 = time.time()
            runs[name] = episode(build_dir, Path(tmp) / name, url, rtf)
            runs[name]["test_wall_s"] = round(time.time() - t0, 1)
        keys = ("red_light_violations", "stop_sign_violations", "collisions", "laps_completed",
                "sim_s", "wall_s", "test_wall_s", "first_moved_s", "driven_in_window_m")  # fmt: skip
        print(json.dumps({n: {k: r.get(k) for k in keys} for n, r in runs.items()}, indent=1))
        full, paced = runs["full"], runs["paced_0.1x"]
        for key in ("red_light_violations", "stop_sign_violations", "collisions"):
            assert full[key] == paced[key], f"{key}: {full[key]} at full speed, {paced[key]} paced"
        assert full["laps_per_car"] == paced["laps_per_car"], "laps differ"
        d_full, d_paced = full["driven_in_window_m"], paced["driven_in_window_m"]
        assert isinstance(d_full, dict) and isinstance(d_paced, dict)
        for car in d_full:
            assert abs(d_full[car] - d_paced[car]) <= TOLERANCE_M, (
                f"{car} drove {d_full[car]:.3f} m in its {WINDOW_S:g} s window at full speed, "
                f"{d_paced[car]:.3f} m paced at 0.1x (tolerance {TOLERANCE_M} m)"
            )
            assert d_full[car] > 0.05, f"{car} hardly drove ({d_full[car]:.3f} m)"
