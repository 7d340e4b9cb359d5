"""Where the project's single sources live, found from this package's own location."""

from pathlib import Path

REPO_ROOT: Path = Path(__file__).resolve().parents[2]
VEHICLE_FILE: Path = REPO_ROOT / "vehicle" / "nigel.params"
CHANNEL_TABLE: Path = REPO_ROOT / "lcm_types" / "channels.yaml"
RUNTIME_HIL_CONFIG: Path = REPO_ROOT / "runtime" / "jetson" / "config" / "nigel_hil.yaml"
RUNTIME_CAR_CONFIG: Path = REPO_ROOT / "runtime" / "jetson" / "config" / "nigel_car.yaml"
AUTONOMY_EXAMPLE_CONFIG: Path = (
    REPO_ROOT / "runtime" / "jetson" / "config" / "autonomy.example.yaml"
)
EYE_CONFIG: Path = REPO_ROOT / "eye" / "config" / "eye.yaml"
EYE_SIM_CONFIG: Path = REPO_ROOT / "eye" / "config" / "sim" / "eye.yaml"
RELEASE_BUILD: Path = REPO_ROOT / "build" / "release"
OUT_DIR: Path = REPO_ROOT / "out"
