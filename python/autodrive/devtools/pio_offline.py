"""PlatformIO offline: registers firmware/nano/pio/tool-scons (SCons from PyPI) as PlatformIO's
core package `tool-scons`, so `pio run -e nano_offline` needs nothing from PlatformIO's registry.

PlatformIO Core runs every build through its `tool-scons` package (`<pkg>/scons.py`). We link
the package folder into the core dir as PlatformIO's own `pio pkg install symlink://...` does
(a `.pio-link` file), with the owner `platformio` that Core asks for; the CLI cannot set an
owner on a symlinked package. Run by tools/setup; idempotent.
usage: python -m autodrive.devtools.pio_offline [--core-dir DIR]
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path

from autodrive.core.settings import settings

TOOL_SCONS_DIR = settings().tool_scons_dir


def default_core_dir() -> Path:
    """PlatformIO's core dir: $PLATFORMIO_CORE_DIR, else ~/.platformio (as PlatformIO does)."""
    env = os.environ.get("PLATFORMIO_CORE_DIR")
    return Path(env) if env else Path.home() / ".platformio"


def link_record(package_dir: Path) -> dict[str, object]:
    """The .pio-link content PlatformIO reads for a symlinked package owned by `platformio`."""
    return {
        "cwd": str(package_dir.parent),
        "spec": {
            "owner": "platformio",
            "id": None,
            "name": "tool-scons",
            "requirements": None,
            "uri": "symlink://" + str(package_dir),
        },
    }


def ensure_tool_scons(core_dir: Path, package_dir: Path = TOOL_SCONS_DIR) -> Path:
    """Writes <core_dir>/packages/tool-scons.pio-link -> package_dir (only if it differs)."""
    if not (package_dir / "package.json").is_file():
        raise FileNotFoundError(f"{package_dir}: no package.json (is this the repo root?)")
    packages = core_dir / "packages"
    if (packages / "tool-scons").is_dir():
        raise FileExistsError(
            f"{packages / 'tool-scons'} exists (a tool-scons from PlatformIO's registry): "
            "remove it to use the project's offline one"
        )
    packages.mkdir(parents=True, exist_ok=True)
    link = packages / "tool-scons.pio-link"
    want = json.dumps(link_record(package_dir.resolve()))
    if not link.is_file() or link.read_text(encoding="utf-8") != want:
        link.write_text(want, encoding="utf-8")
    return link


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        description="Registers the project's tool-scons (SCons from PyPI) with PlatformIO Core."
    )
    ap.add_argument("--core-dir", type=Path, default=None, help="PlatformIO core dir")
    args = ap.parse_args(argv)
    core_dir: Path = args.core_dir if args.core_dir is not None else default_core_dir()
    try:
        link = ensure_tool_scons(core_dir)
    except (FileNotFoundError, FileExistsError) as e:
        print(f"pio_offline: {e}", file=sys.stderr)
        return 1
    print(f"pio_offline: tool-scons -> {TOOL_SCONS_DIR} ({link})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
