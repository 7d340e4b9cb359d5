"""The expert recording: the simulator's route driver (pure pursuit on a named route's lane
centre line, seeded steering perturbations so recoveries are in the data) drives N laps in
lockstep with the front camera on, and lcm-logger records the bus into one LCM log. Beside it,
LOG.meta.json says what was recorded (map, route, seed, ...): `tools/pilot record` reads it."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import asdict, dataclass
from pathlib import Path

from autodrive.core import lcmtypes, seeds
from autodrive.maps import road_styles
from autodrive.core.settings import RELEASE_BUILD
from autodrive.core.proc import die_with_parent, stop

META_SUFFIX = ".meta.json"


@dataclass(frozen=True)
class ExpertRun:
    map: str = "driving_school"
    route: str = "loop_ccw"
    # lanes to the route's left, driven in the route's direction (1 on a two-lane loop: its
    # other lane; the simulator's `lane_shift`)
    lane_shift: int = 0
    laps: int = 5
    seed: int = seeds.CLONING_EXPERT_SEED  # a training seed
    speed: float = 0.8  # throttle, fraction of top speed
    lookahead_m: float = 0.2  # pure pursuit's lookahead [m]
    perturb: float = 0.35  # steering perturbation amplitude, normalised
    # [Hz] of sim time: rendering is ~96 % of a recording's CPU; every frame is trained on
    camera_fps: float = 7.5
    camera_noise: float = 2.0  # sigma [8-bit levels]: the training condition's sensor noise
    light_level: float = 1.0  # day
    camera_blur: float = 0.0  # Gaussian blur sigma [px] of the rendered frames (0: none)
    duration_s: float = 0.0  # [s] of sim time: stop early (0: when the laps are done)
    # how the road is painted (domain randomisation; None: the map's own textures)
    road_style: road_styles.RoadStyle | None = None
    # the simulator's other randomisation (autodrive-sim options of the same names)
    light_rgb: tuple[float, ...] | None = None  # a gain per channel, 0.5..1.5
    camera_exposure_ev: float = 0.0  # [EV] frames x 2^EV
    camera_jitter: tuple[float, ...] | None = None  # the mount's offset [mm] and turn [deg]
    distractors: int = 0  # static objects beside the road, placed from the seed


def meta_path(log: Path) -> Path:
    return log.with_name(log.name + META_SUFFIX)


def default_url(k: int = 0) -> str:
    """A multicast port of our own (k: the k-th of this process's recordings, 0 or 1), so two
    recordings on one machine do not mix."""
    return f"udpm://239.255.76.67:{7800 + 2 * (os.getpid() % 150) + k}?ttl=0"


def sim_binary(build: Path) -> Path:
    b = build / "bin" / "autodrive-sim"
    if not b.is_file():
        raise FileNotFoundError(
            f"{b} is missing: build it (cmake --build {build} -t autodrive-sim)"
        )
    return b


def sim_argv(
    run: ExpertRun, build: Path, url: str, run_dir: Path, texture_dir: Path | None = None
) -> list[str]:
    script = (
        f"route:{run.route},speed={run.speed:g},lookahead={run.lookahead_m:g},"
        f"laps={run.laps},perturb={run.perturb:g}"
        + (f",lane_shift={run.lane_shift}" if run.lane_shift else "")
    )
    return [
        str(sim_binary(build)),
        "--map", run.map,
        "--lockstep", "--no-pty", "--no-lidar", "--front-camera",
        "--camera-fps", f"{run.camera_fps:g}",
        "--camera-noise", f"{run.camera_noise:g}",
        "--light-level", f"{run.light_level:g}",
        *(["--camera-blur", f"{run.camera_blur:g}"] if run.camera_blur > 0 else []),
        *(["--texture-dir", str(texture_dir)] if texture_dir else []),
        *(["--light-rgb", ",".join(f"{g:g}" for g in run.light_rgb)] if run.light_rgb else []),
        *(["--camera-exposure", f"{run.camera_exposure_ev:g}"] if run.camera_exposure_ev else []),
        *(["--camera-jitter", f"{run.camera_jitter[0]:g},{run.camera_jitter[1]:g}"]
          if run.camera_jitter else []),
        *(["--distractors", str(run.distractors)] if run.distractors else []),
        "--script", script,
        "--seed", str(run.seed),
        "--lcm-url", url,
        "--run-dir", str(run_dir),
    ] + (["--duration", f"{run.duration_s:g}", "--quiet"] if run.duration_s > 0 else [])  # fmt: skip


def record_expert(run: ExpertRun, log: Path, build: Path = RELEASE_BUILD, url: str = "") -> float:
    """Drives and records; returns the wall time [s]. Progress lines go to stderr. ValueError
    for a seed outside the training range (what a cloning evaluation must never run on)."""
    seeds.require(run.seed, ("training",), "the expert recording's seed")
    if log.exists():
        raise FileExistsError(f"{log} exists, not overwriting")
    if shutil.which("lcm-logger") is None:
        raise FileNotFoundError("lcm-logger not found (Debian package liblcm-bin)")
    log.parent.mkdir(parents=True, exist_ok=True)
    url = url or default_url()
    t0 = time.monotonic()
    with tempfile.TemporaryDirectory(prefix="pilot-expert-") as tmp:
        tex = None
        if run.road_style is not None:
            tex = road_styles.write_texture_dir(run.map, run.road_style, Path(tmp) / "road")
        argv = sim_argv(run, build, url, Path(tmp) / "run", tex)
        logger = subprocess.Popen(
            [*lcmtypes.logger_argv(url, "--channel=.*"), str(log)],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            start_new_session=True,
            preexec_fn=die_with_parent(),
        )
        try:
            time.sleep(0.5)  # the logger subscribed before the first frame
            print(f"pilot expert: {' '.join(argv)}", file=sys.stderr, flush=True)
            sim = subprocess.Popen(
                argv, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True
            )
            assert sim.stdout is not None
            lines: list[str] = []
            for line in sim.stdout:
                lines.append(line)
                if "t = " in line or "done" in line:  # the sim's progress lines
                    print(f"pilot expert: {line.strip()}", file=sys.stderr, flush=True)
            code = sim.wait()
            if code != 0:
                raise RuntimeError(f"autodrive-sim exited with {code}: {''.join(lines[-5:])}")
            time.sleep(0.5)  # the last frames reach the logger
        finally:
            stop(logger, "lcm-logger", lambda m: print(m, file=sys.stderr))
    wall_s = time.monotonic() - t0
    meta = dict(asdict(run), source="expert", sim_argv=argv, wall_s=round(wall_s, 2))
    # the mount offsets the simulator drew (its one line per car), for the dataset's manifest
    meta["camera_jitter_drawn"] = [x.strip() for x in lines if "(--camera-jitter)" in x] or None
    meta_path(log).write_text(json.dumps(meta, indent=2) + "\n")
    return wall_s
