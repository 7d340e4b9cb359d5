"""tools/bench learn: the learning API's speed on one process, with HIL's physics step (1 ms).
Progress on stderr; figures on stdout, the last line one JSON object. Needs AUTODRIVE_BUILD.

env_steps_per_s_1car: ParkingEnv (Gymnasium, Parking School) at a 20 Hz control period (50
physics steps per env step), random actions drawn beforehand, resets included; *_lidar360:
the same with a 360-ray LIDAR scan in every observation; *_lane_keeping: LaneKeepingEnv
(Driving School, loop_ccw). bare_env_steps_per_s_*: the bound MuJoCo alone sets, bare mj_step
steps per second on that map / 50. *_cpu: per second of this process's CPU time (a loaded,
shared machine). agent_steps_per_s_4cars: IntersectionEnv (PettingZoo; Intersection School,
or Parking School until that map exists), 4 cars, agent steps per second; *_2proc: the sum of
two such processes running at once.
api_overhead_ratio: wall time of the batch API (step_worlds) stepping 4 one-car worlds by 50 ms
over a bare mj_step loop on the same model and state for the same number of steps, taken
within one run, median of the runs (*_cpu: thread CPU time instead of wall time).
batch_cost_ratio: one step_worlds call over 8 worlds against 8 single World.step calls
(thread CPU time); batch_speedup_2threads: wall time of that batch on one thread over the same
on two (step_worlds(..., threads=2)).
physics_steps_per_s_1car and bare_mj_step_per_s_1car: the figures behind the ratio.
goals_met: the issue's goals (>= 1000 env steps/s, >= 800 agent steps/s, ratio <= 1.15), by
wall time and by CPU time. Options: LEARN_BENCH_SECONDS (5) per figure, LEARN_BENCH_REPEATS
(3)."""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from autodrive.bench import Progress, build_dir, print_figures
from autodrive.core import seeds
from autodrive.bench.goals import at_least, at_most, judge

UNSEEDED = seeds.unseeded("throughput: steps per second, the same whatever the seed")
# The goals, by wall time and by CPU time (a loaded machine), and the batch API's cost
GOALS = {
    "env_steps_per_s_1car": at_least("env_steps_per_s_1car", 1000),
    "env_steps_per_s_1car_cpu": at_least("env_steps_per_s_1car_cpu", 1000),
    "agent_steps_per_s_4cars": at_least("agent_steps_per_s_4cars", 800),
    "agent_steps_per_s_4cars_cpu": at_least("agent_steps_per_s_4cars_cpu", 800),
    "api_overhead_ratio": at_most("api_overhead_ratio", 1.15),
    "api_overhead_ratio_cpu": at_most("api_overhead_ratio_cpu", 1.15),
    "batch_cost_ratio": at_most("batch_cost_ratio", 1.0),
}

log = Progress("learn")
CONTROL_MS = 50  # 20 Hz
BATCH_WORLDS = 4
BATCH_COMPARE_WORLDS = 8
ACTIONS = 997  # pre-drawn random actions, cycled


def rate(step: Callable[[], int], seconds: float) -> tuple[float, float]:
    """Units per wall second and per CPU second of step() (which returns the units it did)."""
    done, t0, c0 = 0, time.perf_counter(), time.process_time()
    while time.perf_counter() - t0 < seconds:
        done += step()
    return done / (time.perf_counter() - t0), done / (time.process_time() - c0)


def gym_rate(seconds: float, lidar_rays: int, lane_keeping: bool) -> tuple[float, float]:
    from autodrive.gym.envs import LaneKeepingEnv, ParkingEnv

    env = (
        LaneKeepingEnv(lidar_rays=lidar_rays) if lane_keeping else ParkingEnv(lidar_rays=lidar_rays)
    )
    env.reset(seed=0)
    # random actions drawn beforehand: the agent's cost (Box.sample is ~20 us) is not the env's
    actions = np.random.default_rng(0).uniform(-1, 1, (ACTIONS, 2)).astype(np.float32)
    k = 0

    def one() -> int:
        nonlocal k
        _, _, term, trunc, _ = env.step(actions[k % ACTIONS])
        k += 1
        if term or trunc:
            env.reset()
        return 1

    r = rate(one, seconds)
    env.close()
    return r


def pz_rate(seconds: float, cars: int = 4) -> tuple[tuple[float, float], str]:
    from autodrive.gym.pz_env import IntersectionEnv

    env = IntersectionEnv(cars=cars)
    env.reset(seed=0)
    actions = np.random.default_rng(0).uniform(-1, 1, (ACTIONS, 2)).astype(np.float32)
    k = 0

    def one() -> int:
        nonlocal k
        acts = {a: actions[(k + i) % ACTIONS] for i, a in enumerate(env.agents)}
        k += len(acts) + 1
        env.step(acts)
        if not env.agents:
            env.reset()
        return len(acts)

    r = rate(one, seconds)
    env.close()
    return r, env.map_name


def bare_env_rate(map_name: str) -> float:
    """Env steps per second MuJoCo alone allows on map_name: bare mj_step rate / 50."""
    from autodrive.gym.world import World

    w = World(map_name)
    steps = 5000
    return steps / w.bare_mj_step_s(steps) / CONTROL_MS


def api_overhead(seconds: float) -> dict[str, float]:
    """Batch API vs bare mj_step, interleaved in one run (wall and thread CPU)."""
    from autodrive.gym.world import World, step_worlds

    worlds = [World("parking_school", seed=k) for k in range(BATCH_WORLDS)]
    for w in worlds:
        w.command(0, 0.5, 0.3)
    step_worlds(worlds, 500)  # armed and rolling
    batches = max(1, int(seconds * 40))
    steps = batches * CONTROL_MS * BATCH_WORLDS
    t0, c0 = time.perf_counter(), time.thread_time()
    for _ in range(batches):
        step_worlds(worlds, CONTROL_MS)
    api_s, api_cpu = time.perf_counter() - t0, time.thread_time() - c0
    c0 = time.thread_time()
    bare_s = sum(w.bare_mj_step_s(steps // BATCH_WORLDS) for w in worlds)
    bare_cpu = time.thread_time() - c0
    return {
        "ratio": api_s / bare_s,
        "ratio_cpu": api_cpu / bare_cpu,
        "api_steps_per_s": steps / api_s,
        "bare_steps_per_s": steps / bare_s,
    }


def batch_cost(seconds: float) -> tuple[float, float]:
    """One step_worlds call over K worlds / K single steps (same worlds, alternating, thread
    CPU time); and the wall-time speed-up of the same batch on 2 threads."""
    from autodrive.gym.world import World, step_worlds

    worlds = [World("parking_school", seed=k) for k in range(BATCH_COMPARE_WORLDS)]
    rounds = max(1, int(seconds * 2))
    single = batch = batch_wall = threaded_wall = 0.0
    for _ in range(rounds):  # thread CPU time: the machine's load does not enter the ratio
        t0 = time.thread_time()
        for w in worlds:
            w.step(CONTROL_MS)
        single += time.thread_time() - t0
        t0, w0 = time.thread_time(), time.perf_counter()
        step_worlds(worlds, CONTROL_MS)
        batch += time.thread_time() - t0
        batch_wall += time.perf_counter() - w0
        w0 = time.perf_counter()
        step_worlds(worlds, CONTROL_MS, threads=2)
        threaded_wall += time.perf_counter() - w0
    return batch / single, batch_wall / threaded_wall


def two_processes(seconds: float) -> float:
    argv = [sys.executable, "-m", "autodrive.bench", "learn", "--worker", str(seconds)]
    procs = [subprocess.Popen(argv, stdout=subprocess.PIPE, text=True) for _ in range(2)]
    total = 0.0
    for p in procs:
        out, _ = p.communicate()
        if p.returncode != 0:
            raise RuntimeError(f"bench learn worker failed ({p.returncode})")
        total += float(json.loads(out.strip().splitlines()[-1])["agent_steps_per_s"])
    return total


def main(argv: list[str]) -> int:
    seconds = float(os.environ.get("LEARN_BENCH_SECONDS", "5"))
    if argv[:1] == ["--worker"]:  # one of the two processes of *_2proc
        (r, _), _ = pz_rate(float(argv[1]))
        print(json.dumps({"agent_steps_per_s": r}), flush=True)
        return 0
    if argv:
        print(__doc__.strip())
        return 0 if argv[0] in ("-h", "--help") else 2
    build_dir("learn")
    repeats = int(os.environ.get("LEARN_BENCH_REPEATS", "3"))
    res: dict[str, Any] = {}
    runs: dict[str, list[float]] = {}

    def keep(key: str, value: float) -> None:
        runs.setdefault(key, []).append(value)

    for k in range(repeats):
        for suffix, lidar, lane in (
            ("", 0, False),
            ("_lidar360", 360, False),
            ("_lane_keeping", 0, True),
        ):
            wall, cpu = gym_rate(seconds, lidar, lane)
            keep(f"env_steps_per_s_1car{suffix}", wall)
            keep(f"env_steps_per_s_1car{suffix}_cpu", cpu)
        keep("bare_env_steps_per_s_1car", bare_env_rate("parking_school"))
        keep("bare_env_steps_per_s_1car_lane_keeping", bare_env_rate("driving_school"))
        (wall, cpu), map_name = pz_rate(seconds)
        keep("agent_steps_per_s_4cars", wall)
        keep("agent_steps_per_s_4cars_cpu", cpu)
        o = api_overhead(seconds)
        keep("api_overhead_ratio", o["ratio"])
        keep("api_overhead_ratio_cpu", o["ratio_cpu"])
        keep("physics_steps_per_s_1car", o["api_steps_per_s"])
        keep("bare_mj_step_per_s_1car", o["bare_steps_per_s"])
        cost, speedup = batch_cost(seconds)
        keep("batch_cost_ratio", cost)
        keep("batch_speedup_2threads", speedup)
        keep("agent_steps_per_s_4cars_2proc", two_processes(seconds))
        log(f"run {k + 1}/{repeats}: " + ", ".join(f"{key} {v[-1]:.3g}" for key, v in runs.items()))
    for key, values in runs.items():
        digits = 3 if "ratio" in key else 1
        res[key] = round(statistics.median(values), digits)
    res["multi_car_map"] = map_name
    res["control_period_ms"] = CONTROL_MS
    res["physics_step_ms"] = 1
    print_figures(judge(res, GOALS, UNSEEDED), key_value_lines=True)
    return 0
