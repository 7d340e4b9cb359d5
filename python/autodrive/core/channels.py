"""Reads the channel table (lcm_types/channels.yaml), the one place channel names are written.

Usage: ``channel("COMMAND", "NIGEL1") == "NIGEL1_COMMAND"``, ``channel("SIM_CLOCK")``.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import yaml

from autodrive.core.settings import CHANNEL_TABLE

VEH = "<VEH>"
CAM = "<CAM>"  # an overhead camera of the map (EYE1, EYE2, ...: the map's eye_cameras)
# Conditions of a channel's optional "when": published only on maps with traffic lights, only
# when someone acts (a command), only when a runtime knows its map pose (v2v: an Eye or
# estimator.initial_pose_map), or only while the Smart City Manager runs. "" = every run.
# eye_cameras: only when the simulator renders a map's several overhead cameras. cameras: only
# with the cars' cameras on; sim_eye: only with autodrive-sim --eye; paced: only when the
# simulator publishes its clock (--lockstep*, --rtf). eye_lockstep: only while an Eye runs in
# lockstep with the simulator (--sim-latency-ms).
WHEN = frozenset(
    {"", "traffic_lights", "on_demand", "v2v", "smart_city", "eye_cameras", "cameras", "sim_eye",
     "paced", "eye_lockstep"}
)  # fmt: skip
# What an audit without a named run assumes: a full run, cameras, the simulated Eye and a clock.
FULL_RUN = frozenset({"cameras", "sim_eye", "paced"})


class ChannelTableError(ValueError):
    """A channel table that cannot be read, or a lookup of a channel it does not list."""


@dataclass(frozen=True)
class Channel:
    name: str  # pattern, "<VEH>_..." per vehicle, "<CAM>_..." per overhead camera
    id: str
    type: str
    rate: str
    status: str  # live or planned
    publishers: tuple[str, ...]
    subscribers: tuple[str, ...]
    content: str
    when: str = ""  # "": every run; else the condition under which it is published
    # Signed channels: the certificate roles that may send it (autodrive.core.v2x_auth), and
    # whether the certificate's name must be the message's `vehicle` (V2V). () = not signed.
    signed_by: tuple[str, ...] = ()
    signer_is_vehicle: bool = False

    @property
    def per_vehicle(self) -> bool:
        return self.name.startswith(VEH + "_")

    @property
    def per_camera(self) -> bool:
        return self.name.startswith(CAM + "_")

    @property
    def placeholder(self) -> str:
        """<VEH> or <CAM> for a channel per vehicle or per camera, else ""."""
        return VEH if self.per_vehicle else CAM if self.per_camera else ""

    def resolve(self, vehicle: str | None = None) -> str:
        """The concrete channel name; per-vehicle (per-camera) channels need the vehicle
        (camera) name."""
        if self.placeholder:
            if not vehicle:
                raise ChannelTableError(f"channel {self.name} needs a {self.placeholder} name")
            return vehicle.upper() + self.name[len(self.placeholder) :]
        return self.name


@dataclass(frozen=True)
class InstanceRule:
    """How a session's instance number moves its ports (channels.yaml `instances`)."""

    variable: str  # the environment variable holding the instance number
    max: int  # the largest instance number
    port_step: int  # instance N adds N * port_step to the LCM and the web port
    web_port: int  # instance 0's web port (the Smart City Manager's)
    sim_run_dir: str  # instance 0's simulator run dir; instance N's is <this>-N


@dataclass(frozen=True)
class RunKind:
    """A kind of recorded run (channels.yaml `runs`): who publishes and what holds in it."""

    name: str
    programs: frozenset[str]  # the publishers (program names of the table) that run
    when: frozenset[str]  # the conditions (WHEN) that hold

    def expects(self, ch: Channel) -> bool:
        """Whether this kind of run publishes the live channel ch."""
        runs = any(p in self.programs for p in ch.publishers)
        return ch.status == "live" and runs and (not ch.when or ch.when in self.when)


@dataclass(frozen=True)
class ChannelTable:
    source: Path
    url_default: str
    vehicle_prefix: str
    channels: tuple[Channel, ...]
    instances: InstanceRule
    runs: tuple[RunKind, ...] = ()

    def run(self, name: str) -> RunKind:
        for r in self.runs:
            if r.name == name:
                return r
        known = ", ".join(r.name for r in self.runs)
        raise ChannelTableError(f"{self.source}: no run kind '{name}' (runs: {known})")

    def by_id(self, channel_id: str) -> Channel:
        for ch in self.channels:
            if ch.id == channel_id:
                return ch
        raise ChannelTableError(f"{self.source}: no channel with id '{channel_id}'")

    def match(self, concrete: str) -> Channel | None:
        """The table entry a concrete name (e.g. NIGEL2_ODOM) belongs to, or None."""
        for ch in self.channels:
            if ch.placeholder:
                suffix = ch.name[len(ch.placeholder) :]
                prefix = concrete[: -len(suffix)] if concrete.endswith(suffix) else ""
                # a vehicle (camera) name is capitals and digits, no underscore
                # (NIGEL1_LASER_ODOM is LASER_ODOM of NIGEL1, not ODOM of NIGEL1_LASER)
                if prefix and prefix.isalnum() and prefix.isupper():
                    return ch
            elif ch.name == concrete:
                return ch
        return None


_FIELDS = (
    "name",
    "id",
    "type",
    "rate",
    "status",
    "publishers",
    "subscribers",
    "content",
)


@lru_cache(maxsize=None)
def load(path: Path | str | None = None) -> ChannelTable:
    """Reads and checks the table; raises ChannelTableError naming the file and entry."""
    source = Path(path) if path is not None else CHANNEL_TABLE
    try:
        doc = yaml.safe_load(source.read_text())
    except (OSError, yaml.YAMLError) as err:
        raise ChannelTableError(f"{source}: cannot read the channel table ({err})") from err
    if not isinstance(doc, dict) or not isinstance(doc.get("channels"), list):
        raise ChannelTableError(f"{source}: expected a mapping with a 'channels' list")
    out = []
    for i, entry in enumerate(doc["channels"]):
        missing = [f for f in _FIELDS if not isinstance(entry, dict) or f not in entry]
        if missing:
            raise ChannelTableError(f"{source}: channels[{i}] lacks {', '.join(missing)}")
        if entry.get("when", "") not in WHEN:
            raise ChannelTableError(
                f"{source}: channels[{i}] ({entry['name']}): when must be one of {sorted(WHEN)[1:]}"
            )
        if entry["status"] not in ("live", "planned"):
            raise ChannelTableError(
                f"{source}: channels[{i}] ({entry['name']}): status must be live or planned"
            )
        out.append(
            Channel(
                name=str(entry["name"]),
                id=str(entry["id"]),
                type=str(entry["type"]),
                rate=str(entry["rate"]),
                status=str(entry["status"]),
                publishers=tuple(entry["publishers"]),
                subscribers=tuple(entry["subscribers"]),
                content=str(entry["content"]),
                when=str(entry.get("when", "")),
                signed_by=tuple(str(r) for r in entry.get("signed_by", ())),
                signer_is_vehicle=bool(entry.get("signer_is_vehicle", False)),
            )
        )
    return ChannelTable(
        source=source,
        url_default=str(doc.get("url_default", "")),
        vehicle_prefix=str(doc.get("vehicle_prefix", "")),
        channels=tuple(out),
        instances=_instance_rule(source, doc.get("instances")),
        runs=_runs(source, doc.get("runs", {})),
    )


def _runs(source: Path, entry: object) -> tuple[RunKind, ...]:
    if not isinstance(entry, dict):
        raise ChannelTableError(f"{source}: 'runs' must map run names to programs and when")
    out = []
    for name, r in entry.items():
        if not isinstance(r, dict) or not isinstance(r.get("programs"), list):
            raise ChannelTableError(f"{source}: runs.{name}: needs a 'programs' list")
        when = frozenset(str(w) for w in r.get("when", []))
        if not when <= WHEN:
            raise ChannelTableError(f"{source}: runs.{name}.when: unknown {sorted(when - WHEN)}")
        out.append(RunKind(str(name), frozenset(str(p) for p in r["programs"]), when))
    return tuple(out)


def _instance_rule(source: Path, entry: object) -> InstanceRule:
    keys = ("variable", "max", "port_step", "web_port", "sim_run_dir")
    if not isinstance(entry, dict) or any(k not in entry for k in keys):
        raise ChannelTableError(f"{source}: 'instances' needs {', '.join(keys)}")
    try:
        return InstanceRule(
            variable=str(entry["variable"]),
            max=int(entry["max"]),
            port_step=int(entry["port_step"]),
            web_port=int(entry["web_port"]),
            sim_run_dir=str(entry["sim_run_dir"]),
        )
    except (TypeError, ValueError) as err:
        raise ChannelTableError(f"{source}: 'instances': {err}") from err


def channel(channel_id: str, vehicle: str | None = None) -> str:
    """The concrete name of a channel by its id, e.g. channel("ODOM", "NIGEL1")."""
    return load().by_id(channel_id).resolve(vehicle)


def vehicle_name(car: int = 1) -> str:
    """The name of the simulator's car number car (1, 2, ...), e.g. "NIGEL1"."""
    return f"{load().vehicle_prefix}{car}"
