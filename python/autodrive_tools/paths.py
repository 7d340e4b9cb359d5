"""Where the project's single sources live, found from this package's own location."""

from pathlib import Path

REPO_ROOT: Path = Path(__file__).resolve().parents[2]
VEHICLE_FILE: Path = REPO_ROOT / "vehicle" / "nigel.params"
CHANNEL_TABLE: Path = REPO_ROOT / "lcm_types" / "channels.yaml"
