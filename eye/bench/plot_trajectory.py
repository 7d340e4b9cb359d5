#!/usr/bin/env python3
"""Plots the benchmark trajectory: truth vs the Eye (and the OpenCV aruco peer), with the
position error along the drive. Usage: plot_trajectory.py <csv from eye_bench> <out.png>"""
import csv
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    rows = list(csv.DictReader(open(sys.argv[1])))
    if not rows:
        sys.exit(f"{sys.argv[1]}: no rows")

    def col(name):
        return [float(r[name]) if r[name] else math.nan for r in rows]

    tx, ty = col("true_x_m"), col("true_y_m")
    ex, ey = col("eye_x_m"), col("eye_y_m")
    px, py = col("peer_x_m"), col("peer_y_m")
    err_eye = [1000 * math.hypot(a - b, c - d) for a, b, c, d in zip(ex, tx, ey, ty)]
    err_peer = [1000 * math.hypot(a - b, c - d) for a, b, c, d in zip(px, tx, py, ty)]
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(13, 5), gridspec_kw={"width_ratios": [1.4, 1]})
    a1.plot(tx, ty, "-", color="0.6", lw=3, label="truth (base_link)")
    a1.plot(ex, ey, ".", color="tab:blue", ms=3, label="Eye (libapriltag, roof plane)")
    a1.plot(px, py, "x", color="tab:red", ms=2, alpha=0.5, label="peer (OpenCV aruco)")
    a1.set_xlabel("map x [m]")
    a1.set_ylabel("map y [m]")
    a1.set_aspect("equal")
    a1.set_title("Synthesised drive across the 3.0 x 2.0 m map, 1280x720")
    a1.legend(loc="upper right", fontsize=8)
    a2.plot(err_eye, color="tab:blue", lw=1, label="Eye")
    a2.plot(err_peer, color="tab:red", lw=1, alpha=0.6, label="peer (aruco)")
    a2.set_yscale("log")
    a2.set_xlabel("frame")
    a2.set_ylabel("position error [mm]")
    a2.set_title("Position error per frame")
    a2.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(sys.argv[2], dpi=110)


if __name__ == "__main__":
    main()
