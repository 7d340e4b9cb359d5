"""tools/bench parking: the HIL parking demo (sim + unchanged runtime + autodrive-autonomy)
over PARKING_SEEDS seeds (default 10), as jobs on an embedded local Ray (--workers N jobs at a
time, default 1; --address joins a cluster), aggregated against the goals of issue 7 by
autodrive.learn.sweep.parking. Writes out/bench/parking/ (seed<N>/ per run, summary.json,
parking_sweep.png). Options go to the sweep (--help), e.g. --slot K, --extra --realtime."""

from __future__ import annotations

import os
import re
import sys

from autodrive.learn.sweep import parking as sweep
from autodrive.bench import build_dir, out_dir
from autodrive.core import seeds as seed_ranges

GOALS = sweep.GOALS  # judged by the sweep's aggregate (autodrive.bench.goals.judge)

DEFAULT_SEEDS = "10"


def main(argv: list[str]) -> int:
    if any(a in ("-h", "--help") for a in argv):
        print(__doc__.strip() + "\n")
        return sweep.main(["--help"], "tools/bench parking")
    seeds = os.environ.get("PARKING_SEEDS", DEFAULT_SEEDS)
    if not re.fullmatch(r"[1-9][0-9]*", seeds):
        print(
            f"[bench parking] ERROR: PARKING_SEEDS='{seeds}': want a positive integer",
            file=sys.stderr,
        )
        return 2
    # --seeds/--out first: options given to the suite come later and win (argparse keeps
    # the last).
    base = ["--build", str(build_dir("parking")), "--seeds", seeds]
    base += ["--first-seed", str(seed_ranges.EVALUATION.start)]  # figures: evaluation seeds
    return sweep.main(base + ["--out", str(out_dir() / "parking")] + argv, "tools/bench parking")
