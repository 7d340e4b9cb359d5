"""Draws a parking run as a PNG: the occupancy map (map_server PGM+YAML), the grid A* route,
the Hybrid A* path (forward / reverse coloured), the driven trajectory, an optional ground
truth, the goal and the car's footprint at the goal and at the end. Reads the CSVs
autodrive-autonomy writes into its out_dir. CLI: tools/plot-parking --help."""

from __future__ import annotations

import argparse
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from autodrive.core import plots, vehicle
from autodrive.core.cli_numbers import comma_floats
from autodrive.core.geometry import Footprint, Pose, Rect
from autodrive.core.plots import Layer
from autodrive.core.runfiles import has_column, read_columns, read_occupancy


@dataclass
class ParkingRun:
    """The inputs of a parking plot, every pose in the frame of the map."""

    map_yaml: Path
    out: Path
    path_csv: Path | None = None
    route_csv: Path | None = None
    trajectory_csv: Path | None = None
    truth_csv: Path | None = None
    goal: Pose | None = None
    boxes: list[Rect] = field(default_factory=list)  # obstacles not on the map
    footprint: Footprint | None = None


def _path_layers(path_csv: Path) -> list[Layer]:
    p = read_columns(path_csv, ["x_m", "y_m", "yaw_rad", "direction"])
    plan = read_columns(path_csv, ["plan"])["plan"] if has_column(path_csv, "plan") else None
    if plan is None:
        plan = np.ones_like(p["x_m"])
    layers = []
    for k in np.unique(plan):  # every plan: the first one may run through a box seen later
        for d, col, lab in (
            (1, "tab:blue", "path (forward)"),
            (-1, "tab:orange", "path (reverse)"),
        ):
            sel = (p["direction"] == d) & (plan == k)
            xs, ys = np.where(sel, p["x_m"], np.nan), np.where(sel, p["y_m"], np.nan)
            layers.append(Layer(xs, ys, "-", dict(color=col, lw=1.6, label=lab)))
    return layers


def layers(run: ParkingRun) -> list[Layer]:
    fp = run.footprint or vehicle.load().envelope
    out: list[Layer] = []
    if run.route_csv:
        r = read_columns(run.route_csv, ["x_m", "y_m"])
        out.append(Layer(r["x_m"], r["y_m"], ":", dict(color="tab:gray", lw=1.2, label="A* route")))
    if run.path_csv:
        out += _path_layers(run.path_csv)
    if run.truth_csv:
        t = read_columns(run.truth_csv, ["x_m", "y_m"])
        out.append(
            Layer(t["x_m"], t["y_m"], "-", dict(color="tab:green", lw=1.2, label="ground truth"))
        )
    if run.trajectory_csv:
        t = read_columns(run.trajectory_csv, ["x_m", "y_m", "yaw_rad"])
        style = dict(color="tab:red", lw=1.2, label="driven (estimate)")
        out.append(Layer(t["x_m"], t["y_m"], "--", style))
        if len(t["x_m"]):
            end = (t["x_m"][-1], t["y_m"][-1], t["yaw_rad"][-1])
            out.append(Layer(*plots.outline(fp.at(end)), "-", dict(color="tab:red", lw=1.5)))
    if run.goal:
        style = dict(color="tab:purple", lw=1.5, label="goal footprint")
        out.append(Layer(*plots.outline(fp.at(run.goal)), "-", style))
        out.append(Layer([run.goal[0]], [run.goal[1]], "x", dict(color="tab:purple")))
    for box in run.boxes:
        style = dict(color="black", lw=2, label="box not on the map")
        out.append(Layer(*plots.outline(box), "-", style))
    return out


def draw(run: ParkingRun) -> None:
    """Writes run.out; ValueError naming the input that cannot be read."""
    plots.parking(run.out, read_occupancy(run.map_yaml), layers(run))


def _optional_path(v: str | None) -> Path | None:
    return Path(v) if v else None


def main(argv: list[str] | None = None) -> int:
    fp = vehicle.load().envelope
    ap = argparse.ArgumentParser(
        prog="tools/plot-parking",
        description="Plot map, route, planned path and trajectory of an autonomous parking run "
        "to a PNG.",
    )
    ap.add_argument("--map", required=True, help="map_server YAML (its PGM next to it)")
    ap.add_argument(
        "--path",
        help="path.csv from autodrive-autonomy (x_m,y_m,yaw_rad,direction,curvature_1pm)",
    )
    ap.add_argument("--route", help="route.csv (x_m,y_m): the grid A* route")
    ap.add_argument("--trajectory", help="trajectory.csv (t_s,x_m,y_m,yaw_rad,...): estimated pose")
    ap.add_argument("--truth", help="ground-truth CSV with columns x_m,y_m[,yaw_rad]")
    ap.add_argument("--goal", help="goal pose x_m,y_m,yaw_rad")
    ap.add_argument(
        "--footprint",
        default=f"{fp.length_m:g},{fp.width_m:g},{fp.centre_ahead_m:g}",
        help="car length_m,width_m,centre_ahead_of_rear_axle_m (default: the vehicle "
        "description's envelope)",
    )
    ap.add_argument(
        "--box",
        action="append",
        default=[],
        help="an obstacle not on the map, x_m,y_m,yaw_rad,half_x_m,half_y_m (repeatable)",
    )
    ap.add_argument("--out", required=True, help="PNG to write")
    a = ap.parse_args(argv)
    try:
        length_m, width_m, ahead_m = comma_floats(
            a.footprint, 3, "length_m,width_m,centre_ahead_m", "--footprint"
        )
        boxes: list[Rect] = []
        for spec in a.box:
            bx, by, byaw, hx, hy = comma_floats(
                spec, 5, "x_m,y_m,yaw_rad,half_x_m,half_y_m", "--box"
            )
            boxes.append((bx, by, hx, hy, byaw))
        goal = None
        if a.goal:
            gx, gy, gyaw = comma_floats(a.goal, 3, "x_m,y_m,yaw_rad", "--goal")
            goal = (gx, gy, gyaw)
        draw(
            ParkingRun(
                map_yaml=Path(a.map),
                out=Path(a.out),
                path_csv=_optional_path(a.path),
                route_csv=_optional_path(a.route),
                trajectory_csv=_optional_path(a.trajectory),
                truth_csv=_optional_path(a.truth),
                goal=goal,
                boxes=boxes,
                footprint=Footprint(length_m, width_m, ahead_m),
            )
        )
    except ValueError as e:
        print(f"[plot-parking] ERROR: {e}", file=sys.stderr)
        return 1
    print(f"[plot-parking] wrote {a.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
