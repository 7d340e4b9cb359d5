"""The one place that loads the Python LCM types generated at build time
(<build>/lcm_types/gen/python/autodrive_msg: lcm-gen's package `autodrive`, renamed by
lcm_types/CMakeLists.txt so that it does not shadow this distribution) and reads LCM logs.

The generated package is imported from its file location (no sys.path change); it and the
PyPI `lcm` module carry no type information, so they are typed Any here and nowhere else."""

from __future__ import annotations

import importlib.util
import sys
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType
from typing import Any

import lcm

from autodrive.core.settings import instance

PACKAGE = "autodrive_msg"


def generated_dir(build: Path | str) -> Path:
    return Path(build) / "lcm_types" / "gen" / "python"


def load(build: Path | str) -> Any:
    """The generated package `autodrive_msg` of a build dir (its *_t classes as attributes)."""
    loaded = sys.modules.get(PACKAGE)
    if loaded is not None:
        return loaded
    init = generated_dir(build) / PACKAGE / "__init__.py"
    if not init.is_file():
        raise RuntimeError(f"{init} is missing: build the LCM types first (lcm_types target)")
    spec = importlib.util.spec_from_file_location(
        PACKAGE, init, submodule_search_locations=[str(init.parent)]
    )
    if spec is None or spec.loader is None:
        raise RuntimeError(f"{init}: cannot be imported")
    module: ModuleType = importlib.util.module_from_spec(spec)
    sys.modules[PACKAGE] = module  # before exec: its own relative imports look it up
    spec.loader.exec_module(module)
    return module


def bus(url: str) -> Any:
    """An LCM instance on url, moved to the session's instance (AUTODRIVE_INSTANCE)."""
    return lcm.LCM(instance().lcm_url(url))


def logger_argv(url: str, *options: str) -> list[str]:
    """lcm-logger's command line on url moved to the session's instance: Debian's lcm-logger
    knows no AUTODRIVE_INSTANCE, and on the unmoved URL it would record another session's bus."""
    return ["lcm-logger", f"--lcm-url={instance().lcm_url(url)}", *options]


def events(log_path: Path | str) -> Iterator[Any]:
    """The events (channel, timestamp [us of receive time], data) of an LCM log file."""
    yield from lcm.EventLog(str(log_path), "r")
