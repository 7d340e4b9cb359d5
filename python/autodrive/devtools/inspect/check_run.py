"""tools/check-run LOG: what happened in a recorded run (any LCM log of the stack).

Per car: the distance driven (ground truth when the simulator recorded it, else the EKF's
odometry, named), collisions (ground truth's in_collision, counted on each start), who held the
control lease and what the command gate dropped (<VEH>_CONTROL), and the faults the Nano
reported (<VEH>_STATE fault_flags, mode 2 = failsafe). Every channel's message count and rate
over the log's span. Every pose in one frame, the map frame of the map description (the
simulator's world frame): GROUND_TRUTH, POSE_EYE and POSE_AMCL are in it already; POSE_MAP is in
it once the EKF knows its map pose (an Eye fix or estimator.initial_pose_map) and the check
reports its offset from ground truth; ODOM starts at the car's start pose (its own "odom"
frame) and is moved into the map frame by the first ground-truth pose. A PNG of the paths, and
JSON for scripts. With --run KIND (channels.yaml runs: teleop, parking) the bus is also checked
against the channel table for that kind of run. Exit status: 0 a report was made (and the bus
agrees with the table), 1 the log cannot be read or the bus disagrees, 2 bad arguments.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from collections import Counter, defaultdict
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from autodrive.core import channels, lcmtypes
from autodrive.core.settings import RELEASE_BUILD, settings
from autodrive.devtools.inspect import channel_audit

# the pose channels drawn and compared, and the frame each is in as published
POSE_CHANNELS = ("GROUND_TRUTH", "POSE_MAP", "POSE_EYE", "POSE_AMCL", "ODOM")
MODE_FAILSAFE = 2  # vehicle_state_t.mode: 2 failsafe (latched)
MIN_VIEW_M = 2.0  # the picture shows at least this much of the map [m]
ORIGIN_M, ORIGIN_RAD = 1e-3, 1e-3  # a first pose this close to (0, 0, 0): a start frame


@dataclass
class Car:
    name: str
    poses: dict[str, list[tuple[float, float, float, float]]] = field(
        default_factory=lambda: defaultdict(list)
    )  # channel id -> (log time [s], x [m], y [m], yaw [rad]) as published
    collisions: int = 0
    collision_s: float = 0.0  # [s of ground-truth time] in contact
    in_collision: bool = False
    last_truth_s: float | None = None
    holders: list[tuple[float, str]] = field(default_factory=list)  # (log time [s], holder)
    last_control: Any = None
    faults: Counter[int] = field(default_factory=Counter)  # fault bit -> STATE messages with it
    failsafe_s: float | None = None  # log time [s] of the first failsafe mode


def _yaw_of(o: Any) -> float:
    return float(o.yaw_rad)


def _pose_of(cid: str, msg: Any) -> tuple[float, float, float]:
    if cid == "GROUND_TRUTH":
        return float(msg.position_m[0]), float(msg.position_m[1]), _yaw_of(msg)
    return float(msg.x_m), float(msg.y_m), _yaw_of(msg)


def _path_length(track: list[tuple[float, float, float, float]]) -> float:
    return sum(math.dist(a[1:3], b[1:3]) for a, b in zip(track, track[1:]))


def _into(
    origin: tuple[float, float, float], start: tuple[float, ...]
) -> tuple[float, float, float]:
    """The rigid motion (dx, dy, dyaw) that takes a frame whose start pose is start to the
    frame in which the same instant is origin."""
    dyaw = origin[2] - start[2]
    c, s = math.cos(dyaw), math.sin(dyaw)
    return (
        origin[0] - (c * start[0] - s * start[1]),
        origin[1] - (s * start[0] + c * start[1]),
        dyaw,
    )


def _moved(
    p: tuple[float, float, float, float], m: tuple[float, float, float]
) -> tuple[float, float, float, float]:
    c, s = math.cos(m[2]), math.sin(m[2])
    return p[0], m[0] + c * p[1] - s * p[2], m[1] + s * p[1] + c * p[2], p[3] + m[2]


def _nearest(track: list[tuple[float, float, float, float]], t: float) -> tuple[float, ...]:
    return min(track, key=lambda q: abs(q[0] - t))


def read(log: Path, build: Path) -> tuple[dict[str, Car], Counter[str], float, float]:
    """(cars, messages per channel, first and last log time [s]) of the log."""
    table = channels.load()
    types: Any = lcmtypes.load(build)
    cars: dict[str, Car] = {}
    counts: Counter[str] = Counter()
    first = last = None
    for ev in lcmtypes.events(log):
        name, t = str(ev.channel), ev.timestamp * 1e-6
        first = t if first is None else first
        last = t
        counts[name] += 1
        entry = table.match(name)
        if entry is None or not entry.per_vehicle:
            continue
        vehicle = name[: len(name) - (len(entry.name) - len(channels.VEH))]
        car = cars.setdefault(vehicle, Car(vehicle))
        try:
            msg = getattr(types, entry.type).decode(ev.data)
        except (ValueError, AttributeError):  # a malformed message: counted, not read
            continue
        if entry.id in POSE_CHANNELS:
            car.poses[entry.id].append((t, *_pose_of(entry.id, msg)))
        if entry.id == "GROUND_TRUTH":
            ts = msg.utime * 1e-6
            if msg.in_collision and not car.in_collision:
                car.collisions += 1
            if msg.in_collision and car.in_collision and car.last_truth_s is not None:
                car.collision_s += ts - car.last_truth_s
            car.in_collision, car.last_truth_s = bool(msg.in_collision), ts
        elif entry.id == "CONTROL":
            if not car.holders or car.holders[-1][1] != msg.holder:
                car.holders.append((t, str(msg.holder)))
            car.last_control = msg
        elif entry.id == "STATE":
            for bit in range(32):
                if msg.fault_flags & (1 << bit):
                    car.faults[bit] += 1
            if msg.mode == MODE_FAILSAFE and car.failsafe_s is None:
                car.failsafe_s = t
    if first is None or last is None:
        raise ValueError(f"{log}: no messages")
    return cars, counts, first, last


def car_report(car: Car, t0: float) -> dict[str, Any]:
    truth = car.poses.get("GROUND_TRUTH", [])
    odom = car.poses.get("ODOM", [])
    distance_from = "GROUND_TRUTH" if truth else "ODOM" if odom else ""
    out: dict[str, Any] = {
        "distance_m": round(_path_length(truth or odom), 3),
        "distance_from": distance_from or "no pose recorded",
        "collisions": car.collisions if truth else None,
        "collision_s": round(car.collision_s, 3) if truth else None,
        "lease_holders": [
            {"from_s": round(t - t0, 3), "holder": h or "(none)"} for t, h in car.holders
        ],
        "faults": {f"bit {b}": n for b, n in sorted(car.faults.items())},
        "failsafe_at_s": None if car.failsafe_s is None else round(car.failsafe_s - t0, 3),
    }
    c = car.last_control
    if c is not None:
        out["commands"] = {
            "applied": int(c.applied),
            "dropped_unsigned": int(c.dropped_unsigned),
            "dropped_bad_mac": int(c.dropped_bad_mac),
            "dropped_replay": int(c.dropped_replay),
            "dropped_not_holder": int(c.dropped_not_holder),
        }
    out["frames"] = frames(car)
    return out


def starts_at_origin(track: list[tuple[float, float, float, float]]) -> bool:
    """A track whose first pose is (0, 0, 0): an estimate in its own start frame (ODOM always;
    POSE_MAP while the EKF has had no Eye fix and no estimator.initial_pose_map)."""
    if not track:
        return False
    return math.hypot(track[0][1], track[0][2]) < ORIGIN_M and abs(track[0][3]) < ORIGIN_RAD


def frames(car: Car) -> dict[str, Any]:
    """How each pose channel relates to the map frame, checked against ground truth."""
    truth = car.poses.get("GROUND_TRUTH", [])
    moved = in_map_frame(car)
    notes: dict[str, Any] = {}
    for cid, track in sorted(car.poses.items()):
        if cid == "GROUND_TRUTH" or not track:
            continue
        own = starts_at_origin(track)
        note: dict[str, Any] = {
            "frame": "its own start frame (the car's start is 0, 0, 0)" if own else "map"
        }
        if own:
            note["moved_into_map_frame"] = (
                "by the first ground-truth pose" if truth else "no: no ground truth to anchor it"
            )
        if truth:
            sample = moved[cid][:: max(1, len(track) // 200)]
            errs = sorted(math.dist(p[1:3], _nearest(truth, p[0])[1:3]) for p in sample)
            note["median_error_to_ground_truth_m"] = round(errs[len(errs) // 2], 3)
        notes[cid] = note
    return notes


def in_map_frame(car: Car) -> dict[str, list[tuple[float, float, float, float]]]:
    """Every pose track of the car in the map frame: one that starts at the origin (ODOM; a
    POSE_MAP without an Eye fix) is moved by the ground-truth pose at its first message."""
    truth = car.poses.get("GROUND_TRUTH", [])
    out = {}
    for cid, track in car.poses.items():
        if truth and cid != "GROUND_TRUTH" and starts_at_origin(track):
            g = _nearest(truth, track[0][0])
            m = _into((g[1], g[2], g[3]), track[0][1:4])
            out[cid] = [_moved(p, m) for p in track]
        else:
            out[cid] = list(track)
    return out


def rates(counts: Counter[str], span_s: float) -> dict[str, dict[str, Any]]:
    table = channels.load()
    out = {}
    for name, n in sorted(counts.items()):
        entry = table.match(name)
        out[name] = {
            "messages": n,
            "rate_hz": round(n / span_s, 2) if span_s > 0 else None,
            "nominal": entry.rate if entry else "not in the channel table",
        }
    return out


def plot(png: Path, cars: dict[str, Car], map_name: str | None) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 8))
    if map_name:  # the map's floor, lanes and routes (its sidecar JSON), grey under the paths
        sidecar = json.loads((settings().maps_dir / f"{map_name}.json").read_text())
        h = float(sidecar["floor"]["half_size_m"])
        ax.plot([-h, h, h, -h, -h], [-h, -h, h, h, -h], color="0.6", lw=1.0)
        for line in sidecar.get("routes", []) + sidecar.get("lanes", []):
            pts = line.get("polyline_m", [])
            ax.plot([p[0] for p in pts], [p[1] for p in pts], color="0.85", lw=0.8)
    styles = {
        "GROUND_TRUTH": "-",
        "POSE_MAP": "--",
        "POSE_EYE": ".",
        "POSE_AMCL": ":",
        "ODOM": "-.",
    }
    for car in cars.values():
        for cid, track in sorted(in_map_frame(car).items()):
            if track:
                ax.plot([p[1] for p in track], [p[2] for p in track], styles.get(cid, "-"),
                        ms=1.5, lw=1.0, label=f"{car.name} {cid}")  # fmt: skip
    ax.set_aspect("equal")
    x0, x1 = ax.get_xlim()
    y0, y1 = ax.get_ylim()
    if max(x1 - x0, y1 - y0) < MIN_VIEW_M:  # a short run: show its surroundings too
        cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
        ax.set_xlim(cx - MIN_VIEW_M / 2, cx + MIN_VIEW_M / 2)
        ax.set_ylim(cy - MIN_VIEW_M / 2, cy + MIN_VIEW_M / 2)
    ax.set_xlabel("x [m], map frame")
    ax.set_ylabel("y [m], map frame")
    ax.set_title("check-run: every pose in the map frame")
    if ax.lines:
        ax.legend(fontsize=7)
    fig.tight_layout()
    png.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(png, dpi=100)
    plt.close(fig)


def report(log: Path, build: Path, run: str | None = None) -> tuple[dict[str, Any], dict[str, Car]]:
    cars, counts, first, last = read(log, build)
    out: dict[str, Any] = {
        "log": str(log),
        "span_s": round(last - first, 3),
        "cars": {name: car_report(car, first) for name, car in sorted(cars.items())},
        "channels": rates(counts, last - first),
    }
    if run:  # the bus against the channel table, for this kind of run
        out["run"] = run
        out["channel_problems"] = channel_audit.audit(log, build, sorted(cars), run=run)[0]
    return out, cars


def print_report(r: dict[str, Any], out: Any = sys.stdout) -> None:
    print(f"run {r['log']}: {r['span_s']} s of log time", file=out)
    for name, c in r["cars"].items():
        coll = "n/a (no ground truth)" if c["collisions"] is None else (
            f"{c['collisions']} ({c['collision_s']} s in contact)"
        )  # fmt: skip
        print(
            f"{name}: drove {c['distance_m']} m ({c['distance_from']}), collisions {coll}", file=out
        )
        holders = ", ".join(f"{h['holder']} from {h['from_s']} s" for h in c["lease_holders"])
        print(f"  lease holders: {holders or 'none recorded'}", file=out)
        if "commands" in c:
            print(
                "  commands: " + ", ".join(f"{k} {v}" for k, v in c["commands"].items()), file=out
            )
        faults = ", ".join(f"{k} in {v} STATE messages" for k, v in c["faults"].items())
        fs = "" if c["failsafe_at_s"] is None else f"; failsafe from {c['failsafe_at_s']} s"
        print(f"  faults: {faults or 'none'}{fs}", file=out)
        for cid, note in c["frames"].items():
            err = note.get("median_error_to_ground_truth_m")
            how = f", moved into the map frame {note['moved_into_map_frame']}" if "moved_into_map_frame" in note else ""  # fmt: skip
            vs = "" if err is None else f"; median distance to ground truth {err} m"
            print(f"  {cid}: published in {note['frame']}{how}{vs}", file=out)
    if "run" in r:
        problems = r["channel_problems"]
        print(f"channel table, for a {r['run']} run: {len(problems)} problem(s)", file=out)
        for problem in problems:
            print(f"  PROBLEM {problem}", file=out)
    print("channels:", file=out)
    for name, ch in r["channels"].items():
        print(f"  {name:28s} {ch['messages']:8d} msgs {ch['rate_hz']!s:>9} Hz  (nominal {ch['nominal']})", file=out)  # fmt: skip


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(
        prog="tools/check-run",
        description="What happened in a recorded run: per car the distance, collisions, lease "
        "holders and faults; every channel's rate; every pose in the map frame; a PNG.",
        formatter_class=argparse.ArgumentDefaultsHelpFormatter,
    )
    p.add_argument(
        "log", type=Path, help="the LCM log (tools/record, lcm-logger, a demo's run.lcmlog)"
    )
    p.add_argument("--png", type=Path, default=None, help="the picture (default: LOG with .png)")
    p.add_argument("--json", type=Path, default=None, help="also write the report as JSON here")
    p.add_argument(
        "--map", default=None, help="draw this map's lanes under the paths (e.g. parking_school)"
    )
    p.add_argument("--build", type=Path, default=RELEASE_BUILD, help="build dir with the LCM types")
    p.add_argument(
        "--run",
        choices=[r.name for r in channels.load().runs],
        default=None,
        help="the kind of run (channels.yaml runs): also check the bus against the channel "
        "table for it, as channel_audit --run does",
    )
    a = p.parse_args(argv)
    if not a.log.is_file():
        print(f"check-run: {a.log}: no such log", file=sys.stderr)
        return 2
    try:
        r, cars = report(a.log, a.build, a.run)
    except (ValueError, OSError, RuntimeError) as err:
        print(f"check-run: {err}", file=sys.stderr)
        return 1
    png = a.png or a.log.with_suffix(".png")
    plot(png, cars, a.map)
    r["png"] = str(png)
    print_report(r)
    print(f"picture: {png}")
    if a.json:
        a.json.write_text(json.dumps(r, indent=1))
    return 1 if r.get("channel_problems") else 0


if __name__ == "__main__":
    sys.exit(main())
