"""Instructions per simulated step of autodrive-sim, counted by valgrind's callgrind: the
load-independent companion of the rtf figures (on a shared 2-core machine a time ratio moves
with the other jobs; an instruction count does not).

One `autodrive-sim --bench --lockstep --no-pty` run under callgrind gives the inclusive
instructions of the sim's step (`sim_step`, plus the main loop's LCM encoding: ground truth,
SIM_CLOCK, LIDAR scans, light states) and of the bare `mj_step` loop on the same model
(`sim_bare_run`), each divided by its number of steps (the run's JSON: `steps`, `bare_steps`).
"""

from __future__ import annotations

import re
import shutil
import subprocess
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from autodrive.bench import last_json

# the sim's per-step work: the step itself and what the main loop encodes for LCM each step
STEP_FUNCTIONS = (
    "sim_step",
    "publish_ground_truth",
    "publish_sim_clock",
    "publish_lidar_scan",
    "traffic_lights_lcm_publish",
)
BARE_FUNCTION = "sim_bare_run"
LINE = re.compile(r"^\s*([\d,]+)\s+\([^)]*\)\s+\S*?:(\w+)\s")


@dataclass(frozen=True)
class StepInstructions:
    sim_per_step: float  # instructions per 1 ms step of the sim (car, sensors, LCM encoding)
    bare_per_step: float  # instructions per bare mj_step on the same model

    @property
    def overhead_ratio(self) -> float:
        return self.sim_per_step / self.bare_per_step


def available() -> bool:
    return shutil.which("valgrind") is not None and shutil.which("callgrind_annotate") is not None


def _inclusive(annotated: str) -> dict[str, int]:
    out: dict[str, int] = {}
    for line in annotated.splitlines():
        m = LINE.match(line)
        if m and m.group(2) not in out:
            out[m.group(2)] = int(m.group(1).replace(",", ""))
    return out


def measure(sim: Path, args: Sequence[str], duration_s: float) -> StepInstructions:
    """Counts one run of `sim --bench --lockstep --no-pty --duration D ARGS` under callgrind."""
    with tempfile.TemporaryDirectory(prefix="bench-callgrind-") as d:
        out = Path(d) / "callgrind.out"
        argv = ["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", str(sim)]
        argv += ["--quiet", "--bench", "--lockstep", "--no-pty", "--lcm-url", "memq://"]
        argv += ["--run-dir", d, "--duration", f"{duration_s:g}", *args]
        run = subprocess.run(argv, check=True, capture_output=True, text=True).stdout
        annotated = subprocess.run(
            ["callgrind_annotate", "--inclusive=yes", str(out)],
            check=True,
            capture_output=True,
            text=True,
        ).stdout
    counts = last_json(run, "autodrive-sim --bench under callgrind")
    inc = _inclusive(annotated)
    if "sim_step" not in inc or BARE_FUNCTION not in inc:
        raise ValueError("callgrind_annotate listed no sim_step / sim_bare_run (a stripped build?)")
    sim_total = sum(inc.get(f, 0) for f in STEP_FUNCTIONS)
    return StepInstructions(
        sim_total / int(counts["steps"]), inc[BARE_FUNCTION] / int(counts["bare_steps"])
    )
