"""tools/bench opendrive: OpenDRIVE import (autodrive.maps.opendrive). Progress on stderr; figures
on stdout, the last line one JSON object. Needs AUTODRIVE_BUILD (a release build: the
simulator's library drives the routes).

Every fixture network (autodrive.maps.opendrive.fixtures, written by scenariogeneration) is
imported at 1:14 into out/bench/opendrive/, then:
lane_centre_max_dev_mm: the largest distance, at full scale, from a point of the sidecar's lane
  centre lines (taken back to the file's frame by imported_from) to pyxodr's centre line of the
  same lane (autodrive.maps.opendrive.reference), over every lane of every network.
routes_driven_ok / routes_generated: every generated route driven to its end in the simulator's
  library (autodrive.maps.opendrive.drive: real MuJoCo and Nano, the shared pure pursuit at a
  steady throttle) never off its lane (the simulator's off_lane: base_link beyond the route's
  half width) nor in a collision; routes_not_ok lists the others.
import_s: the import's CPU time per network (parse, sample, check, write MJCF + sidecar), median
  over the networks (import_wall_s: the same in wall time, which a loaded machine stretches).
"""

from __future__ import annotations

import argparse
import shutil
import statistics
import time
from typing import Any

import json

from autodrive.bench import Progress, build_dir, out_dir, print_figures
from autodrive.bench.goals import at_most, equals, judge
from autodrive.core import seeds
from autodrive.maps.opendrive import drive, fixtures, importer, reference

SCALE = 1 / 14
UNSEEDED = seeds.unseeded("fixed networks, deterministic import and driving")
GOALS = {
    "lane_centre_max_dev": at_most("lane_centre_max_dev_mm", 10.0),
    "every_route_driven": equals("routes_not_driven_ok", 0),
    "import_s": at_most("import_s", 30.0),
}
log = Progress("opendrive")


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="tools/bench opendrive", description=__doc__.split("\n")[0])
    p.parse_args(argv)
    build_dir("opendrive")  # the simulator's library comes from it
    folder = out_dir() / "opendrive"
    shutil.rmtree(folder, ignore_errors=True)
    files = fixtures.write_all(folder / "xodr")
    dev_m, cpu_s, wall_s = 0.0, [], []
    driven: dict[str, bool] = {}
    per: dict[str, Any] = {}
    for name, path in files.items():
        c0, w0 = time.process_time(), time.monotonic()
        importer.write(path, SCALE, name, folder / "maps")
        cpu_s.append(time.process_time() - c0)
        wall_s.append(time.monotonic() - w0)
        doc = json.loads((folder / "maps" / f"{name}.json").read_text())
        dev = reference.max_centre_deviation_m(path, doc)
        dev_m = max(dev_m, dev)
        log(f"{name}: imported in {cpu_s[-1]:.2f} s CPU, {len(doc['lanes'])} lanes, "
            f"{len(doc['routes'])} routes, centre lines within {dev * 1000:.3f} mm of pyxodr")  # fmt: skip
        for r in doc["routes"]:
            d = drive.drive(folder / "maps" / f"{name}.xml", r["name"],
                            [tuple(q) for q in r["polyline_m"]])  # fmt: skip
            driven[f"{name}/{r['name']}"] = d.ok
            per[f"{name}/{r['name']}"] = {"ok": d.ok, "max_lateral_m": round(d.max_lateral_m, 5),
                                          "half_width_m": d.half_width_m, "sim_s": d.sim_s}  # fmt: skip
            log(f"  {r['name']}: {'ok' if d.ok else 'NOT ok'} (max lateral "
                f"{d.max_lateral_m * 1000:.1f} mm of {d.half_width_m * 1000:.0f}, {d.sim_s:.0f} s sim)")  # fmt: skip
    figures: dict[str, Any] = {
        "networks": len(files),
        "lane_centre_max_dev_mm": round(dev_m * 1000, 4),
        "routes_generated": len(driven),
        "routes_driven_ok": sum(driven.values()),
        "routes_not_driven_ok": len(driven) - sum(driven.values()) if driven else None,
        "routes_not_ok": sorted(k for k, ok in driven.items() if not ok),
        "import_s": round(statistics.median(cpu_s), 3),
        "import_wall_s": round(statistics.median(wall_s), 3),
        "per_route": per,
    }
    print_figures(judge(figures, GOALS, UNSEEDED))
    return 0
