"""A HIL stack for the API tests and benches: autodrive-sim (Parking School, lockstep with the
runtime on its ptys or paced at a real-time factor, SIM_CLOCK published) and the unchanged autodrive-runtime on the sim clock,
on one LCM URL, with the car's command key in $AUTODRIVE_KEY_DIR. With map_pose the EKF is told
where the sim puts the car (the map's spawn), so <VEH>_POSE_MAP (and the ROS bridge's tf
map -> odom) exist without an Eye."""

from __future__ import annotations

from pathlib import Path

import yaml

from autodrive.core import channels, v2x_ca
from autodrive.core.proc import Log, ProcessGroup, wait_for_path
from autodrive.gym import tasks
from autodrive.hil import pose_source
from autodrive.hil.demo import write_runtime_config

MAP = "parking_school"

PTY_TIMEOUT_S = 60.0  # the sim's ptys appear once its scene is built (a guard: CPU-bound start)


def tell_start(cfg_path: Path) -> None:
    """The runtime config's estimator starts at the map's spawn (with a placement's sigma)."""
    cfg = yaml.safe_load(cfg_path.read_text())
    pose_source.estimator_start(cfg, "none", tasks.spawn(MAP))
    cfg_path.write_text(yaml.safe_dump(cfg, sort_keys=False))


def start(
    build: Path,
    work: Path,
    url: str,
    log: Log,
    sim_seconds: float,
    map_pose: bool = False,
    rtf: float | None = None,
) -> ProcessGroup:
    """Starts the sim and the runtime (keys made where missing); the caller stops the group.
    rtf: the sim paced at that real-time factor instead of in lockstep with the runtime (for a
    client slower than a lockstep sim, such as an Octave control loop)."""
    v2x_ca.ensure_run_keys([channels.vehicle_name(1)], log)
    procs = ProcessGroup(log)
    run_dir = work / "sim"
    sim = [build / "bin" / "autodrive-sim", "--map", MAP, "--run-dir", run_dir]
    sim += ["--lcm-url", url, "--no-lidar-lcm", "--duration", sim_seconds]
    sim += ["--lockstep-client"] if rtf is None else ["--rtf", rtf]
    procs.start("autodrive-sim", sim, work / "sim.log")
    try:
        wait_for_path(run_dir / "nigel1-nano", PTY_TIMEOUT_S, procs)
        cfg = write_runtime_config(work, run_dir, url)  # the demo's: on the sim clock
        if map_pose:
            tell_start(cfg)
        procs.start(
            "autodrive-runtime", [build / "bin" / "autodrive-runtime", "--config", cfg],
            work / "runtime.log",
        )  # fmt: skip
    except RuntimeError:
        procs.stop_all()
        raise
    return procs
