"""The SCM's configuration defaults, from the repository settings and the environment: the
database (SQLite under out/scm/ unless --db), the address it serves on, and the build whose
generated LCM types it loads (--build, $AUTODRIVE_BUILD, or the first preset build that has
them)."""

from __future__ import annotations

import os
import sys
from pathlib import Path

from autodrive.core import lcmtypes
from autodrive.core.settings import settings

DEFAULT_MAP = "tiny_town"
DEFAULT_HOST = "127.0.0.1"
BUILD_PRESETS = ("release", "asan", "dev")


def default_sqlite() -> Path:
    return settings().out_dir / "scm" / "scm.sqlite"


def default_url() -> str:
    return f"sqlite:///{default_sqlite()}"


def find_build(given: str | None) -> Path:
    """The build dir with the generated Python LCM types: --build, $AUTODRIVE_BUILD, or the
    first of build/release, build/asan, build/dev that has them."""
    rel = Path("lcm_types/gen/python") / lcmtypes.PACKAGE / "__init__.py"
    if given or os.environ.get("AUTODRIVE_BUILD"):
        path = Path(given or os.environ["AUTODRIVE_BUILD"])
        if not (path / rel).is_file():
            sys.exit(
                f"autodrive-scm: --build {path}: no LCM types there ({rel}); build the "
                "autodrive_lcm_gen target"
            )
        return path
    for preset in BUILD_PRESETS:
        path = settings().preset_build(preset)
        if (path / rel).is_file():
            return path
    sys.exit(
        "autodrive-scm: no build with the LCM types (build/release, asan or dev): build the "
        "autodrive_lcm_gen target or give --build"
    )
