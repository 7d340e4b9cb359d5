"""The one settings object: where the repository's single sources and build trees are.

The package never finds a path from its own location. The repository root is, in order:
1. the environment variable AUTODRIVE_ROOT;
2. the source tree the editable install came from (`pip install -e python/` records it in the
   distribution's direct_url.json: the repository is the parent of python/);
3. the nearest folder at or above the working directory that holds the repository's markers.
The first that holds the markers (vehicle/nigel.params, lcm_types/channels.yaml) wins; none
is an error naming what is missing. AUTODRIVE_BUILD names the host build (default
<root>/build/release).

A session's instance (two users on one machine): ``instance()`` reads AUTODRIVE_INSTANCE (the
variable and the port rule are channels.yaml's `instances`), and ``instance().lcm_url(url)``,
``.web_port(port)`` and ``.sim_run_dir`` give the session's own bus, web port and simulator
run dir; every LCM bus of the distribution opens through it (autodrive.core.lcmtypes.bus).

Usage: ``settings().maps_dir``; the old module constants (REPO_ROOT, RELEASE_BUILD, ...) are
read from it on first use (``from autodrive.core.settings import RELEASE_BUILD``).
"""

from __future__ import annotations

import json
import os
from collections.abc import Callable
from dataclasses import dataclass
from functools import cache
from importlib import metadata
from pathlib import Path
from urllib.parse import unquote, urlparse

DISTRIBUTION = "autodrive"
MARKERS = (Path("vehicle") / "nigel.params", Path("lcm_types") / "channels.yaml")


class SettingsError(RuntimeError):
    """The repository cannot be found: names where it looked and what is missing."""


@dataclass(frozen=True)
class Settings:
    root: Path  # the repository: vehicle/, lcm_types/, maps/, runtime/, eye/, build/
    build: Path  # the host build tree (CMake preset release by default)

    @property
    def vehicle_file(self) -> Path:
        return self.root / "vehicle" / "nigel.params"

    @property
    def channel_table(self) -> Path:
        return self.root / "lcm_types" / "channels.yaml"

    @property
    def maps_dir(self) -> Path:
        """The map descriptions, kit, generated MJCF (.xml), sidecar JSON and textures."""
        return self.root / "maps"

    @property
    def sim_api_header(self) -> Path:
        return self.root / "sim" / "mujoco_hil" / "api" / "include" / "autodrive_sim_api.h"

    @property
    def runtime_config_dir(self) -> Path:
        return self.root / "runtime" / "jetson" / "config"

    @property
    def runtime_hil_config(self) -> Path:
        return self.runtime_config_dir / "nigel_hil.yaml"

    @property
    def runtime_car_config(self) -> Path:
        return self.runtime_config_dir / "nigel_car.yaml"

    @property
    def autonomy_example_config(self) -> Path:
        return self.root / "runtime" / "jetson" / "config" / "autonomy.example.yaml"

    @property
    def eye_config(self) -> Path:
        return self.root / "eye" / "config" / "eye.yaml"

    @property
    def eye_sim_config(self) -> Path:
        return self.root / "eye" / "config" / "sim" / "eye.yaml"

    @property
    def pilot_hil_config(self) -> Path:
        return self.root / "runtime" / "jetson" / "config" / "pilot_hil.yaml"

    @property
    def marl_core_header(self) -> Path:
        return self.root / "common" / "marl_core" / "include" / "autodrive" / "marl_core.h"

    @property
    def path_tracking_header(self) -> Path:
        return self.root / "common" / "path_tracking" / "include" / "autodrive" / "pure_pursuit.h"

    @property
    def road_rules_header(self) -> Path:
        return self.root / "common" / "road_rules" / "include" / "autodrive" / "road_rules.h"

    @property
    def lcm_type_dir(self) -> Path:
        """The message types (lcm_types/autodrive/*_t.lcm)."""
        return self.root / "lcm_types" / "autodrive"

    @property
    def models_dir(self) -> Path:
        """The shipped models (models/marl/intersection.onnx, models/pilot/...)."""
        return self.root / "models"

    @property
    def tool_scons_dir(self) -> Path:
        return self.root / "firmware" / "nano" / "pio" / "tool-scons"

    def preset_build(self, preset: str) -> Path:
        """The build tree of a CMake preset (release, dev, asan)."""
        return self.root / "build" / preset

    @property
    def out_dir(self) -> Path:
        return self.root / "out"


class InstanceError(ValueError):
    """AUTODRIVE_INSTANCE holds no instance number: names the variable, the value and the range."""


@dataclass(frozen=True)
class Instance:
    """A session's instance N: instance 0 keeps the table's ports, N > 0 moves them."""

    number: int
    variable: str  # the environment variable it came from
    port_step: int
    default_lcm_port: int  # url_default's port
    default_web_port: int
    default_sim_run_dir: str

    def lcm_url(self, url: str) -> str:
        """url, moved to this instance when it is a udpm:// URL on the default port."""
        parsed = urlparse(url)
        if self.number == 0 or parsed.scheme != "udpm":
            return url
        port = parsed.port or self.default_lcm_port
        if port != self.default_lcm_port:
            return url  # an explicit other port is the caller's own choice
        host = parsed.hostname or ""
        return parsed._replace(netloc=f"{host}:{port + self.number * self.port_step}").geturl()

    def web_port(self, port: int | None = None) -> int:
        """The web port: the given one, or the default moved to this instance."""
        if port is not None:
            return port
        return self.default_web_port + self.number * self.port_step

    @property
    def sim_run_dir(self) -> str:
        base = self.default_sim_run_dir
        return base if self.number == 0 else f"{base}-{self.number}"

    def describe(self) -> str:
        """One line for error messages: how to pick another instance."""
        return (
            f"this is instance {self.number} ({self.variable}={self.number}); "
            f"run as another instance with {self.variable}=N (0..) or --instance N: "
            f"instance N uses LCM port {self.default_lcm_port}+{self.port_step}*N and web port "
            f"{self.default_web_port}+{self.port_step}*N"
        )


def instance(value: str | None = None) -> Instance:
    """The session's instance, from AUTODRIVE_INSTANCE (or value); raises InstanceError."""
    from autodrive.core import channels  # channels reads its table's path from this module

    table = channels.load()
    rule = table.instances
    text = os.environ.get(rule.variable, "") if value is None else value
    try:
        number = int(text) if text.strip() else 0
    except ValueError:
        number = -1
    if not 0 <= number <= rule.max:
        raise InstanceError(
            f"{rule.variable}='{text}': expected an instance number in 0..{rule.max} "
            "(0, or unset, is the default instance)"
        )
    default_port = urlparse(table.url_default).port
    if default_port is None:
        raise InstanceError(f"{table.source}: url_default names no port: {table.url_default}")
    return Instance(
        number=number,
        variable=rule.variable,
        port_step=rule.port_step,
        default_lcm_port=default_port,
        default_web_port=rule.web_port,
        default_sim_run_dir=rule.sim_run_dir,
    )


def use_instance(number: int) -> None:
    """A program's --instance N: sets AUTODRIVE_INSTANCE for this process and its children."""
    os.environ[instance(str(number)).variable] = str(number)


def _is_repo(path: Path) -> bool:
    return all((path / m).is_file() for m in MARKERS)


def _editable_source() -> Path | None:
    """The folder `pip install -e` was given (python/), from the distribution's direct_url.json."""
    try:
        text = metadata.distribution(DISTRIBUTION).read_text("direct_url.json")
    except metadata.PackageNotFoundError:
        return None
    if not text:
        return None
    url = urlparse(str(json.loads(text).get("url", "")))
    return Path(unquote(url.path)) if url.scheme == "file" else None


def _candidates() -> list[tuple[str, Path]]:
    found: list[tuple[str, Path]] = []
    env = os.environ.get("AUTODRIVE_ROOT")
    if env:
        return [("AUTODRIVE_ROOT", Path(env))]
    source = _editable_source()
    if source is not None:
        found.append(("the editable install's source", source.parent))
    cwd = Path.cwd().resolve()
    found += [("the working directory", p) for p in (cwd, *cwd.parents)]
    return found


@cache
def settings() -> Settings:
    """The settings of this process (read once; AUTODRIVE_ROOT and AUTODRIVE_BUILD first)."""
    tried = _candidates()
    for _, path in tried:
        if _is_repo(path):
            root = path.resolve()
            build = os.environ.get("AUTODRIVE_BUILD")
            return Settings(root, Path(build) if build else root / "build" / "release")
    where = "; ".join(f"{how}: {p}" for how, p in tried[:3])
    missing = " and ".join(str(m) for m in MARKERS)
    raise SettingsError(
        f"cannot find the AutoDRIVE repository (a folder with {missing}); looked at {where}. "
        "Set AUTODRIVE_ROOT to the repository or install it with `pip install -e python/`."
    )


# The module constants of the former autodrive_tools.paths, each one field of settings().
_CONSTANTS: dict[str, Callable[[Settings], Path]] = {
    "REPO_ROOT": lambda s: s.root,
    "VEHICLE_FILE": lambda s: s.vehicle_file,
    "CHANNEL_TABLE": lambda s: s.channel_table,
    "MAPS_DIR": lambda s: s.maps_dir,
    "RUNTIME_HIL_CONFIG": lambda s: s.runtime_hil_config,
    "RUNTIME_CAR_CONFIG": lambda s: s.runtime_car_config,
    "AUTONOMY_EXAMPLE_CONFIG": lambda s: s.autonomy_example_config,
    "EYE_CONFIG": lambda s: s.eye_config,
    "EYE_SIM_CONFIG": lambda s: s.eye_sim_config,
    "RELEASE_BUILD": lambda s: s.build,
    "OUT_DIR": lambda s: s.out_dir,
}


def __getattr__(name: str) -> Path:
    if name in _CONSTANTS:
        return _CONSTANTS[name](settings())
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
