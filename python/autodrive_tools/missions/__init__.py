"""The demo's missions: `loop` (pure pursuit around a stadium track) and `parking`."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from ..proc import Log, ProcessGroup


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
