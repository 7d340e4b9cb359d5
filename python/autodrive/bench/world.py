"""tools/bench world: the simulator's world (maps, routes, traffic lights). Progress on stderr;
figures on stdout, the last line one JSON object. Needs AUTODRIVE_BUILD (a release build).

maps_loaded: maps that load and run 1 s (`autodrive-sim --map NAME`, of the four).
tiles, signs, lights: Tiny Town's counts from its sidecar JSON.
route_cross_track_rms_m / _max_m: every named route of Intersection School and Tiny Town driven
in lockstep by the route driver (`--script route:NAME,speed=0.8`, pure pursuit, real COMMAND
frames into the emulated Nano; `--no-late-obstacles`: a late box may stand in a lane, and the
route driver does not avoid obstacles) to its end (a loop: one lap); the rear-axle centre's distance to
the route, sampled at each 50 Hz command; RMS over all samples of all routes, max over all.
routes_done lists how many reached their end (a route blocked by something in the way does not).
rtf_1_tiny_town / rtf_1: one car with LIDAR and its Nano pty driven by the scripted host bytes
(as tools/bench sim), --lockstep, 20 s, on Tiny Town / Parking School, alternating, medians of
WORLD_BENCH_REPEATS (5) runs; rtf_1_tiny_town_ratio = median of the per-pair ratios; the _cpu
variants divide by the process's CPU time (on a shared, loaded machine the wall figures swing),
the _step_thread_cpu ones by the stepping thread's (without LCM's receive thread, which on a
map with lights reads every message on the bus, the sim's own included, to find the commands).
Routes that do not reach their end (routes_blocked: stuck against something in their lane) are
listed and left out of the cross-track figures.
rtf_1_tiny_town_ratio_instructions: the same ratio in instructions per step (callgrind, 2 s of each
map, the same script; sim_instructions.py): the load-independent figure.
light_cmd_to_state_ms_p50: real time on Intersection School over real UDP LCM: wall time from
publishing a TRAFFIC_LIGHT_COMMAND to receiving the light's TRAFFIC_LIGHT_STATE with the
commanded state, median (and p90, max) of 40 commands.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import select
import statistics
import subprocess
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from autodrive.core import lcmtypes, v2x_auth, v2x_ca
from autodrive.core.channels import channel
from autodrive.core.settings import settings
from autodrive.bench import Progress, build_dir, last_json, print_figures, sim_instructions
from autodrive.core import seeds
from autodrive.bench.goals import at_least, at_most, equals, judge

UNSEEDED = seeds.unseeded("the maps' routes driven by the route driver: deterministic")
# The world's goals; the Tiny Town speed ratio by the stepping thread's CPU time (LCM's receive
# thread reads the whole bus on a map with lights: see the docstring) and in instructions.
GOALS = {
    "maps_loaded": at_least("maps_loaded", 4),
    "route_cross_track_rms": at_most("route_cross_track_rms_m", 0.02),
    "route_cross_track_max": at_most("route_cross_track_max_m", 0.03),
    "every_route_done": equals("routes_not_done", 0),  # a blocked route is left out of the RMS
    "rtf_1_tiny_town_ratio": at_least("rtf_1_tiny_town_ratio_step_thread_cpu", 0.9),
    "rtf_1_tiny_town_ratio_instructions": at_least("rtf_1_tiny_town_ratio_instructions", 0.9),
    "light_cmd_to_state": at_most("light_cmd_to_state_ms_p50", 20),
}

URL = "udpm://239.255.76.67:7758?ttl=0"  # sim's test/bench port range 7730-7759
MAPS = ("parking_school", "driving_school", "intersection_school", "tiny_town")
ROUTE_MAPS = ("intersection_school", "tiny_town")
ROUTE_SPEED = 0.8  # fraction of top speed
TOP_SPEED_M_S = 0.267  # only to cap a route run's duration generously (x2 + 10 s)
RTF_SCRIPT = "constant:throttle=0.5,steering=0.3"
RTF_DURATION_S = 20
LIGHT_COMMANDS = 40
log = Progress("world")


def sidecar(name: str) -> dict[str, Any]:
    path = settings().maps_dir / f"{name}.json"
    doc: dict[str, Any] = json.loads(path.read_text())
    return doc


class WorldBench:
    def __init__(self, build: Path) -> None:
        self.sim = build / "bin" / "autodrive-sim"
        self.types: Any = lcmtypes.load(build)

    def run(self, args: Sequence[str], url: str = "memq://") -> dict[str, Any]:
        with tempfile.TemporaryDirectory(prefix="bench-world-") as run_dir:
            argv = [str(self.sim), "--quiet", "--bench", "--run-dir", run_dir, "--lcm-url", url]
            out = subprocess.run(
                argv + list(args), check=True, capture_output=True, text=True
            ).stdout
        return last_json(out, "autodrive-sim --bench")

    def maps_loaded(self) -> int:
        n = 0
        for m in MAPS:
            try:
                self.run(["--map", m, "--lockstep", "--duration", "1", "--no-pty"])
                n += 1
            except subprocess.CalledProcessError as err:
                log(f"map {m} failed: {err.stderr.strip()[-300:]}")
        return n

    def routes(self) -> dict[str, Any]:
        sum_sq, samples, worst, done, total = 0.0, 0, 0.0, 0, 0
        blocked: list[str] = []
        per_route: dict[str, Any] = {}
        for m in ROUTE_MAPS:
            for r in sidecar(m)["routes"]:
                name = r["name"]
                length = sum(math.dist(a, b) for a, b in zip(r["polyline_m"], r["polyline_m"][1:]))
                cap_s = length / (ROUTE_SPEED * TOP_SPEED_M_S) * 2 + 10
                res = self.run(
                    [
                        "--map",
                        m,
                        "--lockstep",
                        "--no-pty",
                        "--no-lidar",
                        "--no-late-obstacles",  # the route driver does not avoid them
                        "--duration",
                        f"{cap_s:.1f}",
                        "--script",
                        f"route:{name},speed={ROUTE_SPEED}",
                    ]
                )
                n = int(res["route_samples"])
                rms, mx = float(res["route_cross_track_rms_m"]), float(
                    res["route_cross_track_max_m"]
                )
                total += 1
                if res["route_done"]:
                    done += 1
                    sum_sq += rms * rms * n
                    samples += n
                    worst = max(worst, mx)
                else:  # stuck against something in the way: its error is not the driver's
                    blocked.append(f"{m}/{name}")
                per_route[f"{m}/{name}"] = {"rms_m": rms, "max_m": mx, "done": res["route_done"]}
                log(
                    f"{m} route {name}: {length:.2f} m, {'done' if res['route_done'] else 'NOT done'}"
                    f" in {res['sim_s']:.1f} s, cross-track RMS {rms * 1e3:.2f} mm, max {mx * 1e3:.2f} mm"
                )
        return {
            "route_cross_track_rms_m": round(math.sqrt(sum_sq / samples), 5) if samples else None,
            "route_cross_track_max_m": round(worst, 5),
            "routes": total,
            "routes_done": done,
            "routes_not_done": total - done,
            "routes_blocked": blocked,
            "per_route": per_route,
        }

    def rtf(self, repeats: int) -> dict[str, Any]:
        out: dict[str, Any] = {}
        for key in ("rtf", "rtf_cpu", "rtf_step_thread_cpu"):
            out[key] = ([], [], [])
        for k in range(repeats):
            common = ["--lockstep", "--duration", str(RTF_DURATION_S), "--script", RTF_SCRIPT]
            p = self.run(["--map", "parking_school", *common], URL)
            t = self.run(["--map", "tiny_town", *common], URL)
            for key in ("rtf", "rtf_cpu", "rtf_step_thread_cpu"):
                park, town, ratios = out[key]
                park.append(p[key])
                town.append(t[key])
                ratios.append(t[key] / p[key])
            log(
                f"run {k + 1}/{repeats}: rtf_1 parking {p['rtf']:.1f} (CPU {p['rtf_cpu']:.1f}), "
                f"tiny town {t['rtf']:.1f} (CPU {t['rtf_cpu']:.1f})"
            )
        figures: dict[str, Any] = {}
        for key, suffix in (
            ("rtf", ""),
            ("rtf_cpu", "_cpu"),
            ("rtf_step_thread_cpu", "_step_thread_cpu"),
        ):
            park, town, ratios = out[key]
            figures[f"rtf_1{suffix}"] = round(statistics.median(park), 2)
            figures[f"rtf_1_tiny_town{suffix}"] = round(statistics.median(town), 2)
            figures[f"rtf_1_tiny_town_ratio{suffix}"] = round(statistics.median(ratios), 3)
        return figures

    def rtf_instructions(self) -> dict[str, Any]:
        if not sim_instructions.available():
            log("valgrind not installed: no instruction counts")
            return {}
        per_step = {}
        for m in ("parking_school", "tiny_town"):
            log(f"{m}: counting instructions per step under callgrind")
            args = ["--map", m, "--script", RTF_SCRIPT]
            per_step[m] = sim_instructions.measure(self.sim, args, 2.0).sim_per_step
        return {
            "instructions_per_step_parking_school": round(per_step["parking_school"]),
            "instructions_per_step_tiny_town": round(per_step["tiny_town"]),
            "rtf_1_tiny_town_ratio_instructions": round(
                per_step["parking_school"] / per_step["tiny_town"], 4
            ),
        }

    def light_latency(self) -> dict[str, Any]:
        lc = lcmtypes.bus(URL)
        got: list[tuple[float, int, int]] = []  # wall time, light, state
        State, Command = self.types.traffic_light_state_t, self.types.traffic_light_command_t

        scm, bus_clock = v2x_auth.MessageSigner(v2x_ca.load_identity("SCM")), v2x_auth.BusClock()

        def on_state(_c: str, data: bytes) -> None:
            m = State.decode(data)
            got.append((time.monotonic(), m.light_id, m.state))
            bus_clock.heard(m.utime)

        lc.subscribe(channel("TRAFFIC_LIGHT_STATE"), on_state)

        def pump(s: float) -> None:
            end = time.monotonic() + s
            while time.monotonic() < end:
                if select.select([lc.fileno()], [], [], 0.005)[0]:
                    lc.handle()

        lat_ms: list[float] = []
        with tempfile.TemporaryDirectory(prefix="bench-world-") as run_dir:
            sim = subprocess.Popen(
                [
                    str(self.sim),
                    "--map",
                    "intersection_school",
                    "--no-pty",
                    "--quiet",
                    "--run-dir",
                    run_dir,
                    "--lcm-url",
                    URL,
                ],
                stdout=subprocess.DEVNULL,
                stderr=subprocess.PIPE,
            )
            try:
                pump(2.0)
                for k in range(LIGHT_COMMANDS):
                    # light 1 between RED and OFF: never a conflict, always a change
                    want = State.RED if k % 2 == 0 else State.OFF
                    got.clear()
                    msg = Command()
                    msg.utime, msg.light_id, msg.state, msg.duration_s = 0, 1, want, 0.0
                    # signed as the SCM, stamped with the sim time the states tell
                    scm.sign(channel("TRAFFIC_LIGHT_COMMAND"), msg, bus_clock.now_us())
                    t0 = time.monotonic()
                    lc.publish(channel("TRAFFIC_LIGHT_COMMAND"), msg.encode())
                    end = t0 + 1.0
                    while time.monotonic() < end:
                        if select.select([lc.fileno()], [], [], 0.002)[0]:
                            lc.handle()
                        hit = [t for t, i, s in got if i == 1 and s == want]
                        if hit:
                            lat_ms.append((hit[0] - t0) * 1e3)
                            break
                    pump(0.05)
            finally:
                sim.terminate()
                sim.wait(timeout=20)
        if not lat_ms:
            return {"light_cmd_to_state_ms_p50": None}
        lat_ms.sort()
        return {
            "light_cmd_to_state_ms_p50": round(statistics.median(lat_ms), 2),
            "light_cmd_to_state_ms_p90": round(lat_ms[int(0.9 * (len(lat_ms) - 1))], 2),
            "light_cmd_to_state_ms_max": round(lat_ms[-1], 2),
            "light_commands_answered": len(lat_ms),
        }


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="tools/bench world", description=__doc__.split("\n")[0])
    p.add_argument("--skip-rtf", action="store_true", help="leave out the rtf runs")
    args = p.parse_args(argv)
    bench = WorldBench(build_dir("world"))
    town = sidecar("tiny_town")
    figures: dict[str, Any] = {
        "maps_loaded": bench.maps_loaded(),
        "tiles": len(town["tiles"]),
        "signs": len(town["signs"]),
        "lights": len(town["traffic_lights"]),
    }
    log(f"maps loaded: {figures['maps_loaded']} of {len(MAPS)}")
    routes = bench.routes()
    per_route = routes.pop("per_route")
    figures.update(routes)
    if not args.skip_rtf:
        figures.update(bench.rtf(int(os.environ.get("WORLD_BENCH_REPEATS", "5"))))
        figures.update(bench.rtf_instructions())
    figures.update(bench.light_latency())
    for name, r in per_route.items():
        print(
            f"{name}: RMS {r['rms_m'] * 1e3:.2f} mm, max {r['max_m'] * 1e3:.2f} mm"
            + ("" if r["done"] else " (NOT done)")
        )
    print_figures(judge(figures, GOALS, UNSEEDED), key_value_lines=True)
    return 0
