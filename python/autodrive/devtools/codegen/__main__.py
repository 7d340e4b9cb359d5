"""python -m autodrive.devtools.codegen WHAT ...: generated files from the project's descriptions.

  vehicle-header OUT   <autodrive_vehicle.h> for C and C++ (run by CMake at build time)
  channels-header OUT  <autodrive_channels.h> for C and C++ (run by CMake at build time)
  instance-header OUT  <autodrive_instance_rule.h>: the sessions' instance rule (likewise)
  tree [--check]       the generated files kept in the tree (docs, the firmware's servo header):
                       write them, or with --check fail naming each one that is stale
Files are written only when their content changes, so that builds do not redo work."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from autodrive.core import channels, vehicle
from autodrive.core.settings import REPO_ROOT
from autodrive.devtools.codegen import channels_header, tree, vehicle_header


def write_if_changed(path: Path, text: str) -> bool:
    """Writes text to path atomically; returns True if the file changed."""
    if path.is_file() and path.read_text() == text:
        return False
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(path.suffix + ".tmp")
    tmp.write_text(text)
    tmp.replace(path)
    return True


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(
        prog="python -m autodrive.devtools.codegen",
        description=__doc__.split("\n\n")[0] if __doc__ else None,
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog=__doc__,
    )
    sub = p.add_subparsers(dest="what", required=True)
    header = sub.add_parser("vehicle-header", help="write <autodrive_vehicle.h>")
    header.add_argument("out", type=Path, help="the header to write")
    header.add_argument(
        "--params", type=Path, help="vehicle description (default vehicle/nigel.params)"
    )
    ch_header = sub.add_parser("channels-header", help="write <autodrive_channels.h>")
    ch_header.add_argument("out", type=Path, help="the header to write")
    ch_header.add_argument(
        "--table", type=Path, help="channel table (default lcm_types/channels.yaml)"
    )
    inst_header = sub.add_parser(
        "instance-header", help="write <autodrive_instance_rule.h> (channels.yaml's instances)"
    )
    inst_header.add_argument("out", type=Path, help="the header to write")
    inst_header.add_argument(
        "--table", type=Path, help="channel table (default lcm_types/channels.yaml)"
    )
    in_tree = sub.add_parser("tree", help="write (or --check) the generated files in the tree")
    in_tree.add_argument("--check", action="store_true", help="only check that they are fresh")
    in_tree.add_argument("--root", type=Path, default=REPO_ROOT, help="repository root")
    args = p.parse_args(argv)
    try:
        if args.what == "vehicle-header":
            car = vehicle.load(args.params)
            write_if_changed(args.out, vehicle_header.render(car, "vehicle/" + car.source.name))
            return 0
        if args.what == "channels-header":
            table = channels.load(args.table)
            write_if_changed(args.out, channels_header.render(table, tree.CHANNELS))
            return 0
        if args.what == "instance-header":
            table = channels.load(args.table)
            write_if_changed(args.out, channels_header.render_instance(table, tree.CHANNELS))
            return 0
        stale = []
        for rel, text in tree.render_all(args.root).items():
            path = args.root / rel
            if args.check:
                if not path.is_file() or path.read_text() != text:
                    stale.append(rel)
            elif write_if_changed(path, text):
                print(f"codegen: wrote {rel}")
    except (vehicle.VehicleFileError, channels.ChannelTableError) as e:
        print(f"codegen: {e}", file=sys.stderr)
        return 1
    if stale:
        print(
            "codegen: stale generated file(s): " + ", ".join(stale) + " (run tools/gen-docs)",
            file=sys.stderr,
        )
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
