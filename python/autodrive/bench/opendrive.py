"""tools/bench opendrive: OpenDRIVE import (autodrive.maps.opendrive). Progress on stderr; figures
on stdout, the last line one JSON object. Needs AUTODRIVE_BUILD (a release build: its
autodrive-sim, autodrive-runtime and autodrive-city-driver drive the routes).

Every fixture network (autodrive.maps.opendrive.fixtures, written by scenariogeneration) is
imported at 1:14 into out/bench/opendrive/, then:
lane_centre_max_dev_mm: the largest distance, at full scale, from a point of the sidecar's lane
  centre lines (taken back to the file's frame by imported_from) to pyxodr's centre line of the
  same lane (autodrive.maps.opendrive.reference), over every lane of every network.
routes_driven_ok / routes_generated: every generated route driven from its start to its end by
  the smart city's own driver in HIL (autodrive.maps.opendrive.city_drive: autodrive-sim in
  lockstep with autodrive-runtime, the Eye and advisory stand-ins, autodrive-city-driver on the
  imported sidecar, real LCM), the lights on their imported programs: base_link never farther
  from the route's centre line than its half width, no red light or stop sign run (the
  smart-city scorer, autodrive.hil.city.scoring), no collision; routes_not_ok lists the others
  (per_route: max_lateral_at_m_s, where along the route [m] and when [s, sim] base_link was
  farthest from it).
  red_light_violations, stop_sign_violations: summed over the routes; red_stops: the crossings
  of a stop line after standing at it on red (the lights were met and obeyed).
import_s: the import's CPU time per network (parse, sample, check, write MJCF + sidecar), median
  over the networks (import_wall_s: the same in wall time, which a loaded machine stretches).
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import time
from typing import Any

import json

from autodrive.bench import Progress, build_dir, out_dir, print_figures
from autodrive.bench.goals import at_most, equals, judge
from autodrive.core import seeds
from autodrive.maps.opendrive import city_drive, fixtures, importer, reference

SCALE = 1 / 14
PORT = os.environ.get("OPENDRIVE_BENCH_PORT", "7945")  # the city range (docs/INTERFACES.md)
UNSEEDED = seeds.unseeded("fixed networks, deterministic import and driving")
GOALS = {
    "lane_centre_max_dev": at_most("lane_centre_max_dev_mm", 10.0),
    "every_route_driven": equals("routes_not_driven_ok", 0),
    "no_red_light_run": equals("red_light_violations", 0),
    "no_stop_sign_run": equals("stop_sign_violations", 0),
    "import_s": at_most("import_s", 30.0),
}
log = Progress("opendrive")


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="tools/bench opendrive", description=__doc__.split("\n")[0])
    p.parse_args(argv)
    build = build_dir("opendrive")  # the simulator, runtime and city driver come from it
    url = f"udpm://239.255.76.67:{PORT}?ttl=0"
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
        cycle_s = max((t["program"]["cycle_s"] for t in doc["traffic_lights"]), default=0.0)
        for r in doc["routes"]:
            key = f"{name}/{r['name']}"
            d = city_drive.drive_route(folder / "maps" / f"{name}.json", r, build, url,
                                       folder / "runs" / key, lambda m: None, cycle_s)  # fmt: skip
            driven[key] = d.ok
            per[key] = {"ok": d.ok, "reached_end": d.reached_end,
                        "max_lateral_m": round(d.max_lateral_m, 5), "half_width_m": d.half_width_m,
                        "max_lateral_at_m_s": list(d.max_lateral_at),
                        "red_light_violations": d.red_light_violations,
                        "stop_sign_violations": d.stop_sign_violations,
                        "collisions": d.collisions, "red_stops": d.stops_at_red,
                        "sim_s": round(d.sim_s, 1)}  # fmt: skip
            log(f"  {r['name']}: {'ok' if d.ok else 'NOT ok'} (max lateral "
                f"{d.max_lateral_m * 1000:.1f} mm of {d.half_width_m * 1000:.0f}, "
                f"{d.stops_at_red} red stops, {d.sim_s:.0f} s sim)")  # fmt: skip
    figures: dict[str, Any] = {
        "networks": len(files),
        "lane_centre_max_dev_mm": round(dev_m * 1000, 4),
        "routes_generated": len(driven),
        "routes_driven_ok": sum(driven.values()),
        "routes_not_driven_ok": len(driven) - sum(driven.values()) if driven else None,
        "routes_not_ok": sorted(k for k, ok in driven.items() if not ok),
        "red_light_violations": sum(v["red_light_violations"] for v in per.values()),
        "stop_sign_violations": sum(v["stop_sign_violations"] for v in per.values()),
        "red_stops": sum(v["red_stops"] for v in per.values()),
        "import_s": round(statistics.median(cpu_s), 3),
        "import_wall_s": round(statistics.median(wall_s), 3),
        "per_route": per,
    }
    print_figures(judge(figures, GOALS, UNSEEDED))
    return 0
