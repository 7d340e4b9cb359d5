"""tools/bench sweep: the scale-out of tools/sweep on an embedded local Ray. The same parking
sweep (the default demo scenario, SWEEP_SEEDS seeds, default 4) runs with --workers 1 and then
--workers 2; speedup_2_workers = sweep_wall_s with 1 worker / with 2 (from the first job's
submission to the last result, the Ray start-up ray_init_s apart), speedup_2_workers_total the
same with the start-up. agree_1_vs_2: the two reports agree (autodrive.learn.sweep.parking.
disagreements: the same seeds, scenario and success per seed, figures within tolerance).
Writes out/bench/sweep/workers<N>/ (each sweep's runs, summary.json, parking_sweep.png).
Progress on stderr; the last stdout line is one JSON object."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from typing import Any

from autodrive.learn.sweep import parking as sweep
from autodrive.bench import Progress, build_dir, out_dir, print_figures
from autodrive.core import seeds as seed_ranges
from autodrive.bench.goals import at_least, equals, judge

# The scale-out's goals: two workers give the same results as one, and a real speed-up on two
# cores (the start-up of Ray apart).
GOALS = {
    "agree_1_vs_2": equals("agree_1_vs_2", True),
    "speedup_2_workers": at_least("speedup_2_workers", 1.5),
}

DEFAULT_SEEDS = "4"
LCM_URL = "udpm://239.255.76.67:7860?ttl=0"  # jobs take 7860.. (the parking bench: 7846..)


def main(argv: list[str]) -> int:
    if argv:
        print(__doc__.strip())
        return 0 if argv[0] in ("-h", "--help") else 2
    say = Progress("sweep")
    seeds = os.environ.get("SWEEP_SEEDS", DEFAULT_SEEDS)
    if not re.fullmatch(r"[1-9][0-9]*", seeds):
        say(f"ERROR: SWEEP_SEEDS='{seeds}': want a positive integer")
        return 2
    build = build_dir("sweep")
    summaries: dict[int, dict[str, Any]] = {}
    for workers in (1, 2):
        out = out_dir() / "sweep" / f"workers{workers}"
        say(f"parking sweep of {seeds} seeds on a local Ray with {workers} worker(s) -> {out}")
        argv2 = [sys.executable, "-m", "autodrive.learn.sweep.cli", "parking", "--seeds", seeds]
        argv2 += ["--workers", str(workers), "--build", str(build), "--out", str(out)]
        argv2 += ["--lcm-url", LCM_URL]
        r = subprocess.run(argv2, stdout=subprocess.PIPE, text=True)
        if r.returncode != 0:
            say(f"ERROR: the sweep with {workers} worker(s) exited {r.returncode}")
            return 1
        summaries[workers] = json.loads(r.stdout.strip().splitlines()[-1])
    one, two = summaries[1], summaries[2]
    diff = sweep.disagreements(one, two)
    for d in diff:
        say(f"disagreement: {d}")
    total = {w: s["sweep_wall_s"] + s["ray_init_s"] for w, s in summaries.items()}
    figures = {
        "seeds": int(seeds),
        "successes_1_worker": one["successes"],
        "successes_2_workers": two["successes"],
        "sweep_wall_s_1_worker": one["sweep_wall_s"],
        "sweep_wall_s_2_workers": two["sweep_wall_s"],
        "ray_init_s_1_worker": one["ray_init_s"],
        "ray_init_s_2_workers": two["ray_init_s"],
        "run_wall_s_median_1_worker": one["wall_s_median"],
        "run_wall_s_median_2_workers": two["wall_s_median"],
        "speedup_2_workers": round(one["sweep_wall_s"] / two["sweep_wall_s"], 3),
        "speedup_2_workers_total": round(total[1] / total[2], 3),
        "agree_1_vs_2": not diff,
        "cpus": os.cpu_count(),
        "load_average_1min": round(os.getloadavg()[0], 2),
    }
    span = seed_ranges.span(seed_ranges.DEVELOPMENT_MISSION_SEED, int(seeds))
    print_figures(judge(figures, GOALS, span), key_value_lines=True)
    return 0
