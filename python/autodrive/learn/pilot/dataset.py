"""`tools/pilot record`: an LCM log to a dataset. Each front-camera frame becomes a JPEG file
(its bytes as recorded, not re-encoded) and one row of `frames.csv` with the steering and
throttle commanded at its capture time, the speed and the time stamp; `manifest.json` names
the source logs, map, route, seed, frame count and frames per lap (lap index per frame in the
table).

Labels, per frame, the latest sample at or before the frame's capture time (sim time):
- the simulator's ground truth (`<VEH>_GROUND_TRUTH`): `command_steering`/`command_throttle`,
  the COMMAND the car's Nano last took (an expert's, a person's at the teleop, a pilot's), and
  `expert_steering`, the route driver's own pure pursuit steering before any perturbation;
- without ground truth (a log of the real car): the `<VEH>_COMMAND` messages.
`steering` (the training label) is `expert_steering` when the log has it, else the command.
Laps are counted from the ground truth's heading: one more lap each full turn (2 pi) of the
unwrapped yaw since the first frame."""

from __future__ import annotations

import bisect
import csv
import json
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from autodrive.core import channels, lcmtypes
from autodrive.core.settings import RELEASE_BUILD
from autodrive.learn.pilot.expert import meta_path
from autodrive.core.geometry import wrap

TABLE = "frames.csv"
MANIFEST = "manifest.json"
FRAMES_DIR = "frames"
COLUMNS = (
    "frame", "file", "log", "utime_us", "t_s", "steering", "command_steering",
    "expert_steering", "throttle", "speed_m_s", "lap", "perturbed", "x_m", "y_m", "yaw_rad",
)  # fmt: skip
PERTURBED_EPS = 2e-3  # |command - expert| above this: a perturbation was on [normalised]


class RecordError(ValueError):
    """A log we cannot make a dataset of; the message names the log."""


@dataclass
class _Sample:
    utime: int
    steering: float
    throttle: float
    expert: float
    speed: float
    x: float
    y: float
    yaw: float


def _latest(samples: list[_Sample], stamps: list[int], utime: int) -> _Sample | None:
    i = bisect.bisect_right(stamps, utime) - 1
    return samples[i] if i >= 0 else None


def _read_log(log: Path, vehicle: str, types: Any) -> tuple[list[Any], list[_Sample], Any]:
    ch_cam = channels.channel("CAM_FRONT", vehicle)
    ch_gt = channels.channel("GROUND_TRUTH", vehicle)
    ch_cmd = channels.channel("COMMAND", vehicle)
    ch_info = channels.channel("CAM_FRONT_INFO", vehicle)
    frames: list[Any] = []
    truth: list[_Sample] = []
    commands: list[_Sample] = []
    info = None
    try:
        for e in lcmtypes.events(log):
            if e.channel == ch_cam:
                frames.append(types.compressed_image_t.decode(e.data))
            elif e.channel == ch_gt:
                m = types.ground_truth_t.decode(e.data)
                truth.append(
                    _Sample(
                        int(m.utime), float(m.command_steering), float(m.command_throttle),
                        float(m.expert_steering), float(m.linear_velocity_m_s[0]),
                        float(m.position_m[0]), float(m.position_m[1]), float(m.yaw_rad),
                    )
                )  # fmt: skip
            elif e.channel == ch_cmd:
                c = types.vehicle_command_t.decode(e.data)
                commands.append(
                    _Sample(
                        int(c.utime), float(c.steering) if c.engaged else 0.0,
                        float(c.throttle) if c.engaged else 0.0, math.nan, math.nan,
                        math.nan, math.nan, math.nan,
                    )
                )  # fmt: skip
            elif e.channel == ch_info and info is None:
                info = types.camera_info_t.decode(e.data)
    except OSError as e:
        raise RecordError(f"{log}: cannot read it as an LCM log ({e})") from e
    if not frames:
        raise RecordError(f"{log}: no camera frames on {ch_cam}; nothing to learn from")
    labels = truth or commands
    if not labels:
        raise RecordError(f"{log}: neither {ch_gt} nor {ch_cmd}: no steering to label frames")
    labels.sort(key=lambda s: s.utime)
    return frames, labels, info


def _meta(log: Path) -> dict[str, Any]:
    p = meta_path(log)
    if not p.is_file():
        return {}
    try:
        meta: dict[str, Any] = json.loads(p.read_text())
    except json.JSONDecodeError as e:
        raise RecordError(f"{p}: not JSON ({e})") from e
    return meta


def record(
    logs: Sequence[Path],
    out: Path,
    map_name: str | None = None,
    seed: int | None = None,
    vehicle: str | None = None,
    build: Path = RELEASE_BUILD,
    progress: bool = True,
) -> dict[str, Any]:
    """Writes the dataset into out (must not hold one yet); returns the manifest."""
    if (out / MANIFEST).exists():
        raise RecordError(f"{out}: already holds a dataset ({MANIFEST}); give a new --out")
    vehicle = vehicle or channels.vehicle_name(1)
    types = lcmtypes.load(build)
    # check every log before writing anything
    metas = [_meta(log) for log in logs]
    maps = {m.get("map") for m in metas} | ({map_name} if map_name else set())
    maps.discard(None)
    if not maps:
        raise RecordError(
            f"{', '.join(map(str, logs))}: no {meta_path(Path('LOG')).name} beside the log "
            "says the map: give --map NAME"
        )
    if len(maps) > 1:
        raise RecordError(f"logs from different maps {sorted(map(str, maps))}: one map a dataset")
    (out / FRAMES_DIR).mkdir(parents=True, exist_ok=True)
    rows: list[dict[str, Any]] = []
    sources: list[dict[str, Any]] = []
    lap_base = 0
    intrinsics: dict[str, Any] = {}
    for li, log in enumerate(logs):
        if progress:
            print(f"pilot record: reading {log}", flush=True)
        frames, labels, info = _read_log(log, vehicle, types)
        if info is not None and not intrinsics:
            intrinsics = {"width_px": int(info.width_px), "height_px": int(info.height_px),
                          "fx_px": float(info.k[0]), "fy_px": float(info.k[4])}  # fmt: skip
        stamps = [s.utime for s in labels]
        has_truth = not math.isnan(labels[0].yaw)
        yaw0 = prev_yaw = unwrapped = 0.0
        first = True
        n_log = 0
        laps_here = 0
        for f in sorted(frames, key=lambda m: int(m.utime)):
            s = _latest(labels, stamps, int(f.utime))
            if s is None:
                continue  # a frame before the first label: no steering known
            lap = 0
            if has_truth:
                if first:
                    yaw0 = prev_yaw = s.yaw
                    first = False
                d = wrap(s.yaw - prev_yaw)
                unwrapped += d
                prev_yaw = s.yaw
                lap = int(abs(unwrapped) // (2.0 * math.pi))
            laps_here = max(laps_here, lap + 1)
            idx = len(rows)
            name = f"{FRAMES_DIR}/{idx:06d}.jpg"
            (out / name).write_bytes(bytes(f.data))
            expert = s.expert
            label = expert if math.isfinite(expert) else s.steering
            rows.append(
                {
                    "frame": idx, "file": name, "log": li, "utime_us": int(f.utime),
                    "t_s": round((int(f.utime) - int(frames[0].utime)) * 1e-6, 6),
                    "steering": round(label, 5), "command_steering": round(s.steering, 5),
                    "expert_steering": round(expert, 5) if math.isfinite(expert) else "",
                    "throttle": round(s.throttle, 5),
                    "speed_m_s": round(s.speed, 5) if math.isfinite(s.speed) else "",
                    "lap": lap_base + lap,
                    "perturbed": int(math.isfinite(expert) and abs(s.steering - expert) > PERTURBED_EPS),
                    "x_m": round(s.x, 5) if has_truth else "",
                    "y_m": round(s.y, 5) if has_truth else "",
                    "yaw_rad": round(s.yaw, 5) if has_truth else "",
                }
            )  # fmt: skip
            n_log += 1
            if progress and n_log % 1000 == 0:
                print(f"pilot record: {n_log} frames of {len(frames)}", flush=True)
        del yaw0
        sources.append({"log": str(log), "frames": n_log, "laps": laps_here, "meta": metas[li]})
        lap_base += laps_here
    with open(out / TABLE, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=COLUMNS)
        w.writeheader()
        w.writerows(rows)
    per_lap: dict[str, int] = {}
    for r in rows:
        per_lap[str(r["lap"])] = per_lap.get(str(r["lap"]), 0) + 1
    seeds = [m.get("seed") for m in metas]
    manifest: dict[str, Any] = {
        "source_logs": sources,
        "map": maps.pop(),
        "seed": seed if seed is not None else (seeds[0] if len(set(seeds)) == 1 else seeds),
        "vehicle": vehicle,
        "frame_count": len(rows),
        "laps": lap_base,
        "frames_per_lap": per_lap,
        "label": "expert_steering where the log has it, else the commanded steering",
        "camera": intrinsics,
        "table": TABLE,
        "columns": list(COLUMNS),
    }
    (out / MANIFEST).write_text(json.dumps(manifest, indent=2) + "\n")
    if progress:
        print(f"pilot record: {len(rows)} frames, {lap_base} laps -> {out}", flush=True)
    return manifest


@dataclass
class Dataset:
    root: Path
    manifest: dict[str, Any]
    rows: list[dict[str, str]]


def load(root: Path) -> Dataset:
    """A dataset written by `record`; clear errors name the folder and what is missing."""
    mf = root / MANIFEST
    if not mf.is_file():
        raise RecordError(f"{root}: no {MANIFEST}: not a dataset of tools/pilot record")
    manifest = json.loads(mf.read_text())
    with open(root / TABLE, newline="") as fh:
        rows = list(csv.DictReader(fh))
    if len(rows) != manifest["frame_count"]:
        raise RecordError(
            f"{root}: {TABLE} has {len(rows)} rows, the manifest says {manifest['frame_count']}"
        )
    return Dataset(root, manifest, rows)
