"""Scores a recorded smart-city run again from its LCM log: the same scorer as the live mission
(autodrive.hil.city.scoring), fed the log's ground truth and light states in the order they were
recorded. For a run recorded before a scorer fix, or one recorded by hand (tools/record).

    python -m autodrive.hil.city.rescore out/demo/run.lcmlog [--map tiny_town] [--build DIR]

Prints the score as JSON (the report's scoring fields). Exit status: 0 scored, 1 the log or the
map cannot be read or holds no ground truth, 2 bad arguments."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

from autodrive.core import lcmtypes
from autodrive.core.channels import channel
from autodrive.core.settings import RELEASE_BUILD
from autodrive.hil.city.scoring import BLOCKED_S, MapFacts, Scorer
from autodrive.maps.loader import MAPS_DIR


def is_truth(name: str) -> bool:
    """Whether name is some car's ground-truth channel (by the channel table's pattern)."""
    head, _, tail = channel("GROUND_TRUTH", "\0").partition("\0")
    return name.startswith(head) and name.endswith(tail) and len(name) > len(head) + len(tail)


def rescore(log: Path, facts: MapFacts, build: Path) -> dict[str, Any]:
    """The scorer's report of log; raises ValueError when the log holds no ground truth."""
    types = lcmtypes.load(build)
    scorer = Scorer(facts, blocked_s=BLOCKED_S)
    truths = 0
    for ev in lcmtypes.events(log):
        if is_truth(ev.channel):
            m = types.ground_truth_t.decode(ev.data)
            scorer.truth(m.vehicle, m.utime * 1e-6, m.position_m[0], m.position_m[1],
                         m.yaw_rad, m.in_collision)  # fmt: skip
            truths += 1
        elif ev.channel == channel("TRAFFIC_LIGHT_STATE"):
            m = types.traffic_light_state_t.decode(ev.data)
            scorer.light(m.light_id, m.state)
    if truths == 0:
        raise ValueError(
            f"{log}: no {channel('GROUND_TRUTH', '<VEH>')} message (was the simulator on this bus?)"
        )
    return scorer.report()


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(
        prog="python -m autodrive.hil.city.rescore",
        description="Score a recorded smart-city run again from its LCM log (ground truth and "
        "light states) with the live mission's scorer; prints JSON.",
    )
    p.add_argument("log", type=Path, help="the run's LCM log (run.lcmlog)")
    p.add_argument("--map", default="tiny_town", help="the run's map (default tiny_town)")
    p.add_argument("--build", type=Path, default=RELEASE_BUILD, help="host build dir")
    args = p.parse_args(argv)
    map_json = MAPS_DIR / f"{args.map}.json"
    try:
        if not args.log.is_file():
            raise ValueError(f"{args.log}: no such log file")
        if not map_json.is_file():
            raise ValueError(f"--map {args.map}: no {map_json}")
        report = rescore(args.log, MapFacts.load(map_json), args.build)
    except (OSError, ValueError, RuntimeError) as e:
        print(f"rescore: {e}", file=sys.stderr)
        return 1
    print(json.dumps(report, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
