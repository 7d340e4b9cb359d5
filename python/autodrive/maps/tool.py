"""tools/map: look at and check map descriptions (show: a PNG from above; check: validate)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from autodrive.maps.loader import KIT_FILE, MAPS_DIR, load, names
from autodrive.maps.model import MapDescriptionError


def _resolve(arg: str) -> tuple[Path, Path]:
    """A map name or YAML path, and the kit beside it (else the shipped kit)."""
    path = Path(arg) if ("/" in arg or arg.endswith(".yaml")) else MAPS_DIR / f"{arg}.yaml"
    kit = path.parent / KIT_FILE.name
    return path, kit if kit.is_file() else KIT_FILE


def _show(args: argparse.Namespace) -> int:
    from autodrive.maps import show  # matplotlib only when drawing

    path, kit = _resolve(args.map)
    m = load(path, kit)
    out = args.out if args.out is not None else Path(f"{m.name}.png")
    show.draw(m, out, maps_dir=kit.parent)
    print(f"map show: wrote {out}")
    return 0


def _check(args: argparse.Namespace) -> int:
    bad = 0
    for arg in args.files:
        path, kit = _resolve(arg)
        try:
            m = load(path, kit)
        except MapDescriptionError as err:
            print(f"map check: {err}", file=sys.stderr)
            bad += 1
            continue
        print(
            f"map check: {path}: ok ({len(m.tiles)} tiles, {len(m.lanes())} lanes, "
            f"{len(m.all_stop_lines())} stop lines, {len(m.lights())} lights, "
            f"{len(m.signs)} signs, {len(m.named_routes())} routes)"
        )
    return 1 if bad else 0


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(
        prog="tools/map",
        description="Look at and check the map descriptions (maps/<map>.yaml + "
        "kit.yaml). Shipped maps: " + ", ".join(names()) + ".",
    )
    sub = p.add_subparsers(dest="cmd", required=True)
    ps = sub.add_parser(
        "show",
        help="write a PNG of a map from above",
        description="Write a PNG of a map from above: tiles (their textures), lane centre lines "
        "with arrows, stop lines, traffic lights, signs, spawns, parking slots, terrain patches "
        "and obstacles.",
    )
    ps.add_argument("map", help="a shipped map's name (tiny_town) or a description's path")
    ps.add_argument("--out", "-o", type=Path, help="the PNG to write (default: ./<map>.png)")
    ps.set_defaults(run=_show)
    pc = sub.add_parser(
        "check",
        help="validate map descriptions",
        description="Validate map descriptions: structure and types, names, things on the "
        "floor, tiles that connect (lane ends meet within 1 mm), routes that join, stop lines "
        "on their lanes, lights (programs with an all-red interval between crossing lights), "
        "signs. Every error names the file, the element and what is wrong; exit 1 if any "
        "description is bad. Uses the kit.yaml beside a description, else the shipped kit.",
    )
    pc.add_argument("files", nargs="+", help="map names or description paths (.yaml)")
    pc.set_defaults(run=_check)
    args = p.parse_args(argv)
    try:
        return int(args.run(args))
    except MapDescriptionError as err:
        print(f"map {args.cmd}: {err}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
