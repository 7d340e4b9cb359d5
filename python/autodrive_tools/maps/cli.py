"""tools/gen-maps: regenerates every map's MJCF scene and JSON sidecar from its description."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from . import mjcf, sidecar
from .loader import MAPS_DIR, load, names
from .model import MapDescriptionError


def outputs(name: str, maps_dir: Path = MAPS_DIR) -> dict[Path, str]:
    """The generated files of one map (beside its description) and their content."""
    m = load(maps_dir / f"{name}.yaml", maps_dir / "kit.yaml")
    return {
        maps_dir / f"{name}.xml": mjcf.generate(m),
        maps_dir / f"{name}.json": sidecar.generate(m),
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
    p.add_argument(
        "--dir",
        type=Path,
        default=MAPS_DIR,
        help="folder with kit.yaml and the map descriptions (default: %(default)s)",
    )
    args = p.parse_args(argv)
    stale = []
    try:
        if not (args.dir / "kit.yaml").is_file():
            raise MapDescriptionError(f"{args.dir}: no kit.yaml in this folder")
        for name in names(args.dir):
            for path, text in outputs(name, args.dir).items():
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
