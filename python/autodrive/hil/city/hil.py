"""Several cars on one simulator: a runtime config per car (its ptys, the run's bus, the EKF's
start: its first Eye fix, or a given start pose with its placement uncertainty; its route
intent) and the start poses read once from the simulator's ground truth (where it placed each
car, for tests that place cars by hand)."""

from __future__ import annotations

import select
import time
from pathlib import Path
from typing import Any

import yaml

from autodrive.core import lcmtypes
from autodrive.core.channels import channel, vehicle_name
from autodrive.core.settings import RUNTIME_HIL_CONFIG
from autodrive.hil import pose_source

Pose = tuple[float, float, float]  # x [m], y [m], yaw [rad]


def runtime_config(
    out: Path,
    run_dir: Path,
    url: str,
    car: int,
    start: Pose | None,
    route: str,
    lidar: bool = False,
) -> Path:
    """The HIL runtime config of car `car` (1-based) on the sim's ptys, clock sim, its route;
    its EKF placed at start with the placement uncertainty (pose_source.PLACEMENT_STD_M, _RAD),
    or, start None, by its first Eye fix; without the LIDAR unless asked."""
    cfg: dict[str, Any] = yaml.safe_load(RUNTIME_HIL_CONFIG.read_text())
    name = vehicle_name(car)
    cfg["lcm_url"] = url
    cfg["clock"] = "sim"
    cfg["vehicle"]["name"] = name
    cfg["bridge"]["device"] = str(run_dir / f"{name.lower()}-nano")
    if lidar:
        cfg["lidar"]["device"] = str(run_dir / f"{name.lower()}-lidar")
    else:
        del cfg["lidar"]
    pose_source.estimator_start(cfg, "cameras" if start is None else "none", start or (0, 0, 0))
    cfg["route"] = route
    path = out / f"runtime-{name.lower()}.yaml"
    path.write_text(yaml.safe_dump(cfg, sort_keys=False))
    return path


def start_poses(build: Path, url: str, cars: int, timeout_s: float = 30.0) -> list[Pose]:
    """Each car's pose as the simulator placed it (its first ground-truth message): where the
    car was put down, which a real car's operator would type in."""
    types = lcmtypes.load(build)
    lc = lcmtypes.bus(url)
    poses: dict[str, Pose] = {}

    def on_truth(_ch: str, data: bytes) -> None:
        m = types.ground_truth_t.decode(data)
        poses.setdefault(m.vehicle, (m.position_m[0], m.position_m[1], m.yaw_rad))

    names = [vehicle_name(i) for i in range(1, cars + 1)]
    subs = [lc.subscribe(channel("GROUND_TRUTH", n), on_truth) for n in names]
    t0 = time.monotonic()
    while len(poses) < cars:
        if time.monotonic() - t0 > timeout_s:
            missing = [n for n in names if n not in poses]
            raise RuntimeError(f"no ground truth from {missing} within {timeout_s:g} s")
        if select.select([lc.fileno()], [], [], 0.1)[0]:
            lc.handle()
    for s in subs:
        lc.unsubscribe(s)
    return [poses[n] for n in names]
