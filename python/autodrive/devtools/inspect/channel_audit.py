"""Checks a recorded run against the channel table, both ways: every channel on the bus is in
the table with the type the table names (by the LCM fingerprint of its messages) and is not
marked planned; every live channel of the table was published (per-vehicle ones for the vehicles
that ran; with --run NAME only those the table's run kind publishes: its programs, its
conditions). Usage: python -m autodrive.devtools.inspect.channel_audit LOG BUILD
[--vehicle NIGEL1] [--run teleop]"""

from __future__ import annotations

import argparse
import sys
from collections import Counter
from pathlib import Path
from typing import Any

from autodrive.core import channels, lcmtypes

FINGERPRINT_BYTES = 8  # an LCM message starts with its type's 64-bit fingerprint
# The LCM library's own channels: lcm-logger and every LCM instance send LCM_SELF_TEST to check
# that multicast loops back; no program of ours publishes them.
LCM_OWN_CHANNELS = frozenset({"LCM_SELF_TEST"})


def audit(
    log_path: Path,
    build: Path,
    vehicles: list[str],
    conditions: frozenset[str] = frozenset(),
    run: str | None = None,
) -> tuple[list[str], Counter[str]]:
    """(problems, messages per channel) of the LCM log at log_path. A live channel with a
    "when" (e.g. traffic_lights: only maps with lights publish it) is expected only when its
    condition is in conditions; it is checked like any other when it appears. run names a
    kind of run of the table (teleop, parking): only what its programs publish is expected;
    without one, a full run (channels.FULL_RUN) is assumed."""
    table = channels.load()
    kind = (
        table.run(run)
        if run
        else channels.RunKind("", frozenset(p for c in table.channels for p in c.publishers), channels.FULL_RUN)
    )  # fmt: skip
    kind = channels.RunKind(kind.name, kind.programs, kind.when | conditions)
    types: Any = lcmtypes.load(build)
    seen: Counter[str] = Counter()
    problems: list[str] = []
    reported: set[str] = set()
    for event in lcmtypes.events(log_path):
        name = str(event.channel)
        seen[name] += 1
        if name in reported or name in LCM_OWN_CHANNELS:
            continue
        entry = table.match(name)
        if entry is None:
            problems.append(f"{name}: published but not in {table.source.name}")
        elif entry.status == "planned":
            problems.append(f"{name}: published but marked planned in {table.source.name}")
        else:
            want = getattr(types, entry.type)._get_packed_fingerprint()
            if bytes(event.data[:FINGERPRINT_BYTES]) != want:
                problems.append(f"{name}: messages are not of type {entry.type}")
        if problems and problems[-1].startswith(name + ":"):
            reported.add(name)
    for entry in table.channels:
        if not kind.expects(entry):
            continue
        names = [entry.resolve(v) for v in vehicles] if entry.per_vehicle else [entry.name]
        for name in names:
            if name not in seen:
                problems.append(f"{name}: live in {table.source.name} but nobody published it")
    return problems, seen


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(
        prog="python -m autodrive.devtools.inspect.channel_audit",
        description="Check a recorded LCM log against lcm_types/channels.yaml, both ways.",
    )
    p.add_argument("log", type=Path, help="LCM log (lcm-logger)")
    p.add_argument("build", type=Path, help="host build dir (for the generated LCM types)")
    p.add_argument(
        "--vehicle", action="append", default=None, help="vehicle that ran (default NIGEL1)"
    )
    p.add_argument(
        "--when",
        action="append",
        default=[],
        choices=sorted(channels.WHEN - {""}),
        help="a condition of the run (e.g. traffic_lights: its map has lights); live channels "
        "published only then are expected too",
    )
    p.add_argument(
        "--run",
        choices=[r.name for r in channels.load().runs],
        help="the kind of run (lcm_types/channels.yaml runs): expect only what its programs "
        "publish (default: a full run, every live channel)",
    )
    args = p.parse_args(argv)
    if not args.log.is_file():
        print(f"channel_audit: {args.log}: no such log", file=sys.stderr)
        return 2
    problems, seen = audit(
        args.log,
        args.build,
        args.vehicle or [channels.vehicle_name(1)],
        frozenset(args.when),
        args.run,
    )
    for name, n in sorted(seen.items()):
        print(f"{name:24s} {n:8d} messages")
    for problem in problems:
        print(f"PROBLEM {problem}")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
