"""tools/gen-maps: regenerates every map's MJCF scene and JSON sidecar from its description."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from . import mjcf, sidecar
from .loader import MAPS_DIR, load, names
from .model import MapDescriptionError


def outputs(name: str) -> dict[Path, str]:
    """The generated files of one map and their content."""
    m = load(name)
    return {
        MAPS_DIR / f"{name}.xml": mjcf.generate(m),
        MAPS_DIR / f"{name}.json": sidecar.generate(m),
    }


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(
        prog="tools/gen-maps",
        description="Regenerate sim/mujoco_hil/maps/<map>.xml (MJCF) and <map>.json (sidecar for "
        "C/C++ readers) from <map>.yaml and kit.yaml, for every map.",
    )
    p.add_argument(
        "--check",
        action="store_true",
        help="write nothing; exit 1 naming every generated file that is stale or missing",
    )
    args = p.parse_args(argv)
    stale = []
    try:
        for name in names():
            for path, text in outputs(name).items():
                old = path.read_text() if path.is_file() else None
                if old == text:
                    continue
                if args.check:
                    stale.append(path)
                else:
                    path.write_text(text)
                    print(f"gen-maps: wrote {path}")
    except MapDescriptionError as err:
        print(f"gen-maps: {err}", file=sys.stderr)
        return 2
    for path in stale:
        print(f"gen-maps: {path} is stale: run tools/gen-maps and commit it", file=sys.stderr)
    return 1 if stale else 0
