"""Makes the AMCL replay fixture from a parking run (tools/demo or tools/bench parking output):
the saved map cropped to its walls and made 2x coarser, and 8 s of <VEH>_LIDAR and <VEH>_ODOM from the
autonomy's first localisation on, with its first AMCL pose as the start guess.

Usage: make_amcl_fixture.py RUN_DIR BUILD OUT_DIR   (RUN_DIR holds run.lcmlog, map.yaml/.pgm and
autonomy.yaml; then run test_replay_amcl.py ROOT BUILD --update to store the reference)."""

from __future__ import annotations

import json
import pathlib
import sys

import lcm
import numpy as np
import yaml
from PIL import Image

run, build, out = (pathlib.Path(a) for a in sys.argv[1:4])
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "python"))
from autodrive.core import lcmtypes  # noqa: E402
from autodrive.core.channels import channel  # noqa: E402

VEHICLE, WINDOW_S, LEAD_S, MARGIN_CELLS, POOL = "NIGEL1", 8.0, 0.2, 10, 2
OCCUPIED, FREE, UNKNOWN = 0, 254, 205  # the trinary PGM's cells
types = lcmtypes.load(build)
out.mkdir(parents=True, exist_ok=True)

# The map, cropped to its known cells (free or occupied) plus a margin.
meta = yaml.safe_load((run / "map.yaml").read_text())
img = np.asarray(Image.open(run / meta["image"]))
rows, cols = np.nonzero(img == OCCUPIED)
r0, r1 = max(rows.min() - MARGIN_CELLS, 0), min(rows.max() + MARGIN_CELLS + 1, img.shape[0])
c0, c1 = max(cols.min() - MARGIN_CELLS, 0), min(cols.max() + MARGIN_CELLS + 1, img.shape[1])
r0 += (r1 - r0) % POOL  # whole POOL x POOL blocks
c1 -= (c1 - c0) % POOL
crop = img[r0:r1, c0:c1]
# Coarser by POOL (a fixture of a few hundred kB): a block is occupied if any cell is, else free
# if any cell is, else unknown.
blocks = crop.reshape(crop.shape[0] // POOL, POOL, crop.shape[1] // POOL, POOL).swapaxes(1, 2)
blocks = blocks.reshape(blocks.shape[0], blocks.shape[1], POOL * POOL)
pooled = np.where(
    (blocks == OCCUPIED).any(axis=2),
    OCCUPIED,
    np.where((blocks == FREE).any(axis=2), FREE, UNKNOWN),
).astype(np.uint8)
res = float(meta["resolution"])
# PGM row 0 is the top (largest y): the origin moves by the columns cut on the left and the
# rows cut at the bottom.
origin = [
    float(meta["origin"][0] + c0 * res),
    float(meta["origin"][1] + (img.shape[0] - r1) * res),
    0.0,
]
Image.fromarray(pooled).save(out / "amcl_map.pgm")
meta.update(image="amcl_map.pgm", origin=origin, resolution=res * POOL)
(out / "amcl_map.yaml").write_text(yaml.safe_dump(meta, sort_keys=False))

# The window: from just before the first AMCL pose, LIDAR and ODOM only.
ch_amcl, ch_lidar, ch_odom = (channel(c, VEHICLE) for c in ("POSE_AMCL", "LIDAR", "ODOM"))
first = next(
    types.pose2d_t.decode(e.data)
    for e in lcmtypes.events(run / "run.lcmlog")
    if e.channel == ch_amcl
)
t0, t1 = first.utime - int(LEAD_S * 1e6), first.utime + int(WINDOW_S * 1e6)
live = []
dst = lcm.EventLog(str(out / "amcl_input.lcmlog"), "w", overwrite=True)
for e in lcmtypes.events(run / "run.lcmlog"):
    if e.channel in (ch_lidar, ch_odom):
        utime = (
            (types.lidar_scan_t if e.channel == ch_lidar else types.odometry_t).decode(e.data).utime
        )
        if t0 <= utime <= t1:
            dst.write_event(e.timestamp, e.channel, e.data)
    elif e.channel == ch_amcl:
        p = types.pose2d_t.decode(e.data)
        if t0 <= p.utime <= t1:
            live.append([p.utime, p.x_m, p.y_m, p.yaw_rad])
dst.close()
# The run's autonomy config, localising on the cropped map from the first AMCL pose.
config = yaml.safe_load((run / "autonomy.yaml").read_text())
config["map"] = {"load_from": "amcl_map.yaml"}  # the test makes it absolute
config["start"] = {"x_m": first.x_m, "y_m": first.y_m, "yaw_rad": first.yaw_rad}
config.pop("mapping_route", None)
config["out_dir"] = "replay-out"  # the test points it at a temporary folder
(out / "amcl_autonomy.yaml").write_text(yaml.safe_dump(config, sort_keys=False))
(out / "amcl_live.json").write_text(json.dumps({"live_amcl": live}, indent=0) + "\n")
print(
    f"map {pooled.shape[1]}x{pooled.shape[0]} px, window {t0 / 1e6:.2f}..{t1 / 1e6:.2f} s, "
    f"{len(live)} live AMCL poses"
)
