"""The benchmark suites of `tools/bench <suite>`, one module each. A suite's main(argv) prints
progress on stderr, its figures on stdout and, as the last stdout line, one JSON object.
They run through tools/bench, which builds the release preset and sets AUTODRIVE_BUILD."""

from __future__ import annotations

import json
import os
import sys
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

from autodrive.core.settings import settings

SUITES = (
    "apis",
    "cloning",
    "eye",
    "firmware",
    "learn",
    "link",
    "marl",
    "opendrive",
    "parking",
    "scm",
    "security",
    "sim",
    "sweep",
    "v2x",
    "world",
)


def build_dir(suite: str) -> Path:
    """The build the suite measures ($AUTODRIVE_BUILD, set by tools/bench)."""
    build = os.environ.get("AUTODRIVE_BUILD")
    if not build:
        sys.exit(f"[bench {suite}] ERROR: AUTODRIVE_BUILD is unset: run through tools/bench")
    return Path(build)


def out_dir() -> Path:
    """out/bench/ of the repository, for the suites' files."""
    out = settings().out_dir / "bench"
    out.mkdir(parents=True, exist_ok=True)
    return out


class Progress:
    """A suite's progress lines on stderr, "[bench <suite>] ..."."""

    def __init__(self, suite: str) -> None:
        self.prefix = f"[bench {suite}]"

    def __call__(self, msg: str) -> None:
        print(f"{self.prefix} {msg}", file=sys.stderr, flush=True)


def last_json(text: str, what: str) -> dict[str, Any]:
    """The JSON object on the last line of a program's output; ValueError naming the program."""
    lines = text.strip().splitlines()
    try:
        obj = json.loads(lines[-1]) if lines else None
    except ValueError:
        obj = None
    if not isinstance(obj, dict):
        raise ValueError(f"{what} printed no JSON object as its last line")
    return obj


def print_figures(figures: Mapping[str, Any], key_value_lines: bool = False) -> None:
    """The suite's result: optionally "key: value" lines, then the JSON line, last."""
    if key_value_lines:
        for k, v in figures.items():
            print(f"{k}: {v}")
    print(json.dumps(figures), flush=True)


def key_value_main(prog: str, measure: Callable[[], Mapping[str, float]]) -> int:
    """A measurement's CLI end: its figures as "key value" lines on stdout (exit 0), or its
    RuntimeError on stderr as "prog: why" (exit 1)."""
    try:
        fig = measure()
    except RuntimeError as e:
        print(f"{prog}: {e}", file=sys.stderr)
        return 1
    for k, v in fig.items():
        print(f"{k} {v:g}")
    return 0
