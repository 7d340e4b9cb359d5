"""maps.opendrive_drive: an imported OpenDRIVE network (scenariogeneration's crossing, 1:14) loads
in the simulator's library (real MuJoCo, the emulated Nano: autodrive.gym.World), steps, and a
car steered by the shared pure pursuit (the simulator's route driver's rule) drives a generated
route through the junction to its end without the simulator ever finding it off its lane or
in a collision; and its front camera, rendered by the simulator, sees the file's road marks
where the file puts them."""

from __future__ import annotations

import json
import math
import subprocess
from pathlib import Path

import numpy as np

from autodrive.gym import World
from autodrive.maps.opendrive import drive, fixtures, reference
from pyhelpers import REPO_ROOT

TOOL = REPO_ROOT / "tools" / "map"
ROUTE = "r1r1_to_r3r1"  # through the junction, straight on, past light 1


def test_imported_map_loads_steps_and_is_driven(tmp_path: Path) -> None:
    xodr = fixtures.crossing(tmp_path / "crossing.xodr")
    run = subprocess.run([str(TOOL), "import", str(xodr), "--name", "crossing", "--out", str(tmp_path)],
                         capture_output=True, text=True)  # fmt: skip
    assert run.returncode == 0, run.stderr
    doc = json.loads((tmp_path / "crossing.json").read_text())
    world = World(str(tmp_path / "crossing.xml"), cars=1)
    world.reset(0)
    world.step(100)
    assert abs(world.time_s - 0.1) < 1e-9
    world.close()
    route = next(r for r in doc["routes"] if r["name"] == ROUTE)
    done = drive.drive(tmp_path / "crossing.xml", ROUTE, [tuple(p) for p in route["polyline_m"]])
    print(done)
    assert done.reached_end and done.off_lane_steps == 0 and done.collisions == 0, done
    assert done.max_lateral_m < done.half_width_m / 2


def test_drive_scorer_sees_a_planted_lane_departure(tmp_path: Path) -> None:
    """The car steered along the route moved 0.2 m to its right: the simulator's lane test
    (against the true route) must find it off its lane, and the drive must not be ok."""
    xodr = fixtures.crossing(tmp_path / "crossing.xodr")
    subprocess.run([str(TOOL), "import", str(xodr), "--name", "crossing", "--out", str(tmp_path)],
                   check=True, capture_output=True)  # fmt: skip
    doc = json.loads((tmp_path / "crossing.json").read_text())
    route = next(r for r in doc["routes"] if r["name"] == ROUTE)
    pts = [tuple(p) for p in route["polyline_m"]]
    shifted = []
    for (x0, y0), (x1, y1) in zip(pts, pts[1:] + [pts[-1]]):
        if (x0, y0) == (x1, y1):
            shifted.append(shifted[-1])
            continue
        d = ((x1 - x0) ** 2 + (y1 - y0) ** 2) ** 0.5
        shifted.append((x0 + 0.2 * (y1 - y0) / d, y0 - 0.2 * (x1 - x0) / d))
    done = drive.drive(tmp_path / "crossing.xml", ROUTE, shifted, max_sim_s=20.0)
    assert done.off_lane_steps > 0 and not done.ok, done


CAM_FRONT_M = (0.17, 0.0, 0.11)  # nigel%d/cam_front in base_link (vehicle/nigel.params)
CAM_FOVY_DEG = 48.67  # its fovy (sim/mujoco_hil/core/src/mjcf_gen.c)
CAM_PX = (640, 480)
TOLERANCE_PX = 1.5  # a painted line's centre in a row vs where the file puts it


def _rot(q: np.ndarray) -> np.ndarray:
    w, x, y, z = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])  # fmt: skip


def _project(
    world_pts: np.ndarray, pos: np.ndarray, quat: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Pixel coordinates (u right, v down, pixel centres at i + 0.5) of world points in the front
    camera (it looks along the car's +x, image right = the car's -y), and their depth [m]."""
    r = _rot(quat)
    cam = pos + r @ np.array(CAM_FRONT_M)
    rel = (world_pts - cam) @ r  # car axes
    f = CAM_PX[1] / 2 / math.tan(math.radians(CAM_FOVY_DEG / 2))
    u = CAM_PX[0] / 2 - f * rel[:, 1] / rel[:, 0]
    v = CAM_PX[1] / 2 - f * rel[:, 2] / rel[:, 0]
    return np.stack([u, v], axis=1), rel[:, 0]


def test_front_camera_sees_road_marks_where_the_file_puts_them(tmp_path: Path) -> None:
    """The car on road 4 of the crossing (a straight: solid white edges, a broken centre line of
    3 m dashes and 9 m gaps), its front camera rendered by the simulator: in every image row
    0.3-1.2 m ahead, each line of the file (pyxodr's lane borders, taken to ours by
    imported_from) is painted with its centre within 1.5 px of where the file puts it (across
    the line in the image: about 2 mm at 0.8 m ahead, model scale), a broken line only inside its
    dashes (0.1 m full scale from a dash's ends: bare tarmac in its gaps). Rows where the car's
    own red front hides the road are skipped."""
    xodr = fixtures.crossing(tmp_path / "crossing.xodr")
    subprocess.run([str(TOOL), "import", str(xodr), "--name", "crossing", "--out", str(tmp_path)],
                   check=True, capture_output=True)  # fmt: skip
    doc = json.loads((tmp_path / "crossing.json").read_text())
    imp = doc["imported_from"]
    scale, off = imp["scale"], np.array(imp["offset_m"])
    borders = reference.border_lines(xodr)
    lane = next(ln for ln in doc["lanes"] if ln["name"] == "r4_s0_r1")["centre_line"]
    start = lane[int(0.3 / 0.05)]  # 0.3 m along, far from the junction ahead
    world = World(str(tmp_path / "crossing.xml"), cars=1, camera_px=CAM_PX)
    world.reset(0, [(start["x_m"], start["y_m"], start["heading_rad"])])
    world.step(300)  # settled on its wheels
    obs = world.observe(0)
    img = world.camera(0).astype(int)
    world.close()
    checked = {"solid": 0, "dash": 0, "gap": 0}
    for lid in (1, 0, -1):  # the left edge, the centre line, the right edge
        line = borders[("4", 0, lid)][2:-2]  # pyxodr's points, from s = 0 on
        s_m = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(line, axis=0).T))])
        uv, depth = _project(np.column_stack([scale * line + off, np.full(len(line), 7e-4)]),
                             obs.pos_m, obs.quat_wxyz)  # fmt: skip
        width_m = (0.15 if lid == 0 else 0.2) * scale
        dirs = np.gradient(uv, axis=0)
        sin_from_row = np.abs(dirs[:, 1]) / np.hypot(dirs[:, 0], dirs[:, 1])  # the line vs a row
        for (u, v), d, s, across in zip(uv, depth, s_m, sin_from_row):
            if not (0.3 < d < 1.2 and 0 <= u < CAM_PX[0] and 0 <= v < CAM_PX[1]):
                continue
            half = 3 * width_m * CAM_PX[1] / 2 / math.tan(math.radians(CAM_FOVY_DEG / 2)) / d
            row = img[int(v), max(0, int(u - half)) : int(u + half) + 1]
            if ((row[:, 0] > 150) & (row[:, 1] < 80)).any():
                continue  # the car's own red front hides the road there
            paint = row.min(axis=1) > 150  # white on tarmac (~40)
            cols = np.nonzero(paint)[0] + max(0, int(u - half)) + 0.5
            phase = s % 12.0
            if lid == 0 and 0.1 < phase - 3.0 and phase < 12.0 - 0.1:
                assert not paint.any(), (lid, s, d)  # in a gap
                checked["gap"] += 1
            elif lid != 0 or 0.1 < phase < 3.0 - 0.1:
                # the row's paint centre vs the file's line, across the line in the image
                assert paint.any() and abs(cols.mean() - u) * across <= TOLERANCE_PX, (
                    lid,
                    s,
                    d,
                    cols,
                    u,
                )
                checked["dash" if lid == 0 else "solid"] += 1
    print(f"front camera: {checked} points checked")
    assert min(checked.values()) >= 3, checked
