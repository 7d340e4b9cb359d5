"""A HIL stack for the API tests and benches: autodrive-sim (Parking School, lockstep with the
runtime on its ptys, SIM_CLOCK published) and the unchanged autodrive-runtime on the sim clock,
on one LCM URL, with the car's command key in $AUTODRIVE_KEY_DIR."""

from __future__ import annotations

from pathlib import Path

from autodrive.core import channels, v2x_ca
from autodrive.core.proc import Log, ProcessGroup, wait_for_path
from autodrive.hil.demo import write_runtime_config

PTY_TIMEOUT_S = 60.0  # the sim's ptys appear once its scene is built (a guard: CPU-bound start)


def start(build: Path, work: Path, url: str, log: Log, sim_seconds: float) -> ProcessGroup:
    """Starts the sim and the runtime (keys made where missing); the caller stops the group."""
    v2x_ca.ensure_run_keys([channels.vehicle_name(1)], log)
    procs = ProcessGroup(log)
    run_dir = work / "sim"
    sim = [build / "bin" / "autodrive-sim", "--map", "parking_school", "--run-dir", run_dir]
    sim += ["--lcm-url", url, "--lockstep-client", "--no-lidar-lcm", "--duration", sim_seconds]
    procs.start("autodrive-sim", sim, work / "sim.log")
    try:
        wait_for_path(run_dir / "nigel1-nano", PTY_TIMEOUT_S, procs)
        cfg = write_runtime_config(work, run_dir, url)  # the demo's: on the sim clock
        procs.start(
            "autodrive-runtime", [build / "bin" / "autodrive-runtime", "--config", cfg],
            work / "runtime.log",
        )  # fmt: skip
    except RuntimeError:
        procs.stop_all()
        raise
    return procs
