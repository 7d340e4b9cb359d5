"""The demo's missions: `loop` (pure pursuit around a stadium track), `parking`, `smart-city`,
`cloning` and `intersection`, and what they share."""

from __future__ import annotations

import argparse
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from autodrive.core import channels, seeds, settings
from autodrive.core.settings import OUT_DIR, RELEASE_BUILD
from typing import Any

from autodrive.core.proc import ChildExit, Log, ProcessGroup, sanitizer_failures

PTY_TIMEOUT_S = 30.0  # a started simulator's Nano pty appears within this [s wall]
EXIT_INTERRUPTED = 130  # a mission stopped by Ctrl-C exits as a shell's SIGINT does


def add_run_options(
    p: argparse.ArgumentParser, mission: str, seed_help: str, timeout_s: float
) -> None:
    """The options a mission with its own parser shares with the demo: --mission, --build,
    --out (default out/demo-MISSION), --seed, --headless, --timeout [s wall], --lcm-url."""
    p.add_argument("--mission", choices=(mission,), default=mission, help="this mission")
    p.add_argument("--build", default=str(RELEASE_BUILD), help="host build dir")
    p.add_argument("--out", default=str(OUT_DIR / f"demo-{mission}"), help="output folder")
    p.add_argument("--seed", type=int, default=seeds.DEVELOPMENT_MISSION_SEED, help=seed_help)
    p.add_argument("--headless", action="store_true", help="never open the simulator's window")
    p.add_argument("--timeout", type=float, default=timeout_s, help="give up after this [s wall]")
    p.add_argument("--lcm-url", default=channels.load().url_default, help="LCM URL")


def instance_lcm_url(p: argparse.ArgumentParser, url: str) -> str:
    """--lcm-url moved to the session's instance (AUTODRIVE_INSTANCE) once, for every child:
    lcm-logger knows no instance, and with the table's URL it logged another bus than the
    programs' (an empty run.lcmlog: 'no ground truth in the log')."""
    try:
        return settings.instance().lcm_url(url)
    except settings.InstanceError as e:
        p.error(str(e))


def record_children(rep: dict[str, Any], exits: list[ChildExit], say: Log) -> None:
    """Every child's exit code and sanitizer report into a mission's report; a sanitizer report
    (at shutdown too) fails the run: rep["ok"] becomes False."""
    rep["children"] = [e.as_dict() for e in exits]
    rep["sanitizer_reports"] = sanitizer_failures(exits)
    for line in rep["sanitizer_reports"]:
        say(f"FAILED: {line}")
    if rep["sanitizer_reports"]:
        rep["ok"] = False


@dataclass
class MissionContext:
    """What a mission gets from the demo: the build, the bus, the running children."""

    build: Path
    out: Path
    lcm_url: str
    vehicle: str
    procs: ProcessGroup
    stop_requested: Callable[[], bool]
    say: Log  # a progress line of the demo ("[demo] ..." on its console)
    echo: Log  # a line as it is (a child's log)
