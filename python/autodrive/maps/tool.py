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


def _import(args: argparse.Namespace) -> int:
    from autodrive.maps.opendrive import importer  # OpenDRIVE only when importing

    scale = importer.parse_scale(args.scale)
    done = importer.write(args.file, scale, args.name, args.out, args.max_junctions)
    for w in done.warnings:
        print(f"map import: warning: {w}", file=sys.stderr)
    d = done.description
    print(
        f"map import: wrote {args.out / args.name}.yaml, .xml, .json ({len(d['roads'])} lanes, "
        f"{len(d['routes'])} routes, {len(d['traffic_lights'])} lights, {len(d['signs'])} signs; "
        f"ours = {scale:g} * file + {d['imported_from']['offset_m']} m)"
    )
    return 0


def _export(args: argparse.Namespace) -> int:
    from autodrive.maps.opendrive import exporter

    path, kit = _resolve(args.map)
    exporter.write(load(path, kit), args.xodr)
    print(f"map export: wrote {args.xodr}")
    return 0


def _scenario(args: argparse.Namespace) -> int:
    import json
    import os
    import tempfile

    from autodrive.maps.opendrive import scenario

    sidecar = args.map.with_suffix(".json")
    doc = json.loads(sidecar.read_text()) if sidecar.is_file() else {}
    if "imported_from" not in doc:
        raise MapDescriptionError(
            f"{sidecar}: not the sidecar of an imported map (tools/map import)"
        )
    plan = scenario.read(args.file, doc["imported_from"])
    for ent in plan.entities:
        x, y, h = plan.starts[ent]
        speed = plan.speeds_m_s.get(ent)
        print(
            f"map scenario: {ent}: start ({x:.3f}, {y:.3f}) m, yaw {h:.3f} rad, speed {speed} m/s"
        )
    for c in plan.changes:
        when = (
            f"at {c.at_s:g} s" if c.at_s is not None else f"when {c.entity} reaches {c.position_m}"
        )
        print(f"map scenario: event '{c.event}': lights {c.light_ids} -> state {c.state} {when}")
    if args.dry_run:
        return 0
    build = Path(os.environ.get("AUTODRIVE_BUILD", "build/release"))
    url = args.lcm_url
    with tempfile.TemporaryDirectory(prefix="scenario-") as run_dir:
        played = scenario.run(plan, args.map.with_suffix(".xml"), build, url, Path(run_dir),
                              args.duration, lambda m: print(f"map scenario: {m}"))  # fmt: skip
    for lid, states in sorted(played.light_states.items()):
        print(f"map scenario: light {lid}: " + ", ".join(f"{s} from {t:.2f} s" for t, s in states))
    return 0


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
    pi = sub.add_parser(
        "import",
        help="import an OpenDRIVE network as a kit map",
        description="Import an OpenDRIVE (.xodr, 1.4-1.8) network: every driving lane becomes "
        "a lane (its centre line in driving order, its narrowest half width), junction "
        "connections and lane links become successors, routes are every lane-to-lane path "
        "through up to --max-junctions junctions, traffic-light signals become lights at stop "
        "lines, stop/give-way/speed-limit signals become signs (others are listed). Writes "
        "OUT/NAME.yaml, .xml (MJCF), .json (sidecar, with imported_from: file, scale, offset_m: "
        "ours = scale * file + offset_m) and OUT/textures; nothing when the file is refused.",
    )
    pi.add_argument("file", type=Path, help="the .xodr file")
    pi.add_argument(
        "--scale", default="1:14", help="1:14 (default) or a number (ours = scale * file)"
    )
    pi.add_argument("--name", required=True, help="the map's name (letters, digits, _)")
    pi.add_argument("--out", type=Path, required=True, help="the folder to write the map to")
    pi.add_argument("--max-junctions", type=int, default=1, help="junctions per route (default 1)")
    pi.set_defaults(run=_import)
    pe = sub.add_parser(
        "export",
        help="export a kit map as OpenDRIVE 1.7",
        description="Write a kit map as OpenDRIVE 1.7: one road per lane (its centre line as "
        "line and arc geometries, one right lane of the lane's width centred on it by a lane "
        "offset), successors as road links or junctions. Importing it at --scale 1 gives the "
        "same centre lines within 1 mm.",
    )
    pe.add_argument("map", help="a shipped map's name (tiny_town) or a description's path")
    pe.add_argument("--xodr", type=Path, required=True, help="the .xodr file to write")
    pe.set_defaults(run=_export)
    psc = sub.add_parser(
        "scenario",
        help="play an OpenSCENARIO file on an imported map",
        description="Read an OpenSCENARIO file (the subset: Init TeleportAction with "
        "WorldPosition and AbsoluteSpeedAction; events of TrafficSignalStateAction started by "
        "SimulationTimeCondition or ReachPositionCondition; anything else refused by name) on "
        "a map imported by tools/map import, and play it in autodrive-sim: the entities' start "
        "poses and the scripted light changes (signed light commands on the sim's clock).",
    )
    psc.add_argument("file", type=Path, help="the .xosc file")
    psc.add_argument("--map", type=Path, required=True, help="the imported map (DIR/NAME)")
    psc.add_argument("--duration", type=float, default=10.0, help="sim time to play [s]")
    psc.add_argument("--lcm-url", default="udpm://239.255.76.67:7667?ttl=0", help="the LCM bus")
    psc.add_argument("--dry-run", action="store_true", help="print the plan, start nothing")
    psc.set_defaults(run=_scenario)
    args = p.parse_args(argv)
    try:
        return int(args.run(args))
    except MapDescriptionError as err:
        print(f"map {args.cmd}: {err}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
