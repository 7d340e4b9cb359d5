"""The overhead cameras of a simulator map as the Eye sees them: their intrinsics and map poses
from the map's sidecar JSON (its `eye_cameras`, written by tools/gen-maps from the map
description, the one place of each camera), and an `autodrive-eye run` config that serves them
all as one Eye (`cameras:`, one `lcm:<CAM>_IMAGE` source each).

The poses come from the map (the simulator's truth), or from `calibrate-map` on the map's
reference tags (autodrive.bench.eye_refcal). Every camera looks straight down, image up =
map +y (as the MJCF camera's xyaxes say)."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from autodrive.core.channels import channel
from autodrive.maps.loader import MAPS_DIR


@dataclass(frozen=True)
class OverheadCamera:
    name: str  # MJCF camera name (eye1); its channels are <CAM>_IMAGE, <CAM>_CAMERA_INFO
    x_m: float  # optical centre in the map frame [m]
    y_m: float
    z_m: float
    fovy_deg: float
    width_px: int
    height_px: int

    @property
    def f_px(self) -> float:
        return 0.5 * self.height_px / math.tan(math.radians(self.fovy_deg / 2))

    def k(self) -> list[float]:
        """Camera matrix, row-major [px]: MuJoCo's pinhole with the principal point at the
        image centre (OpenCV pixel-centre convention)."""
        f = self.f_px
        return [f, 0, 0.5 * (self.width_px - 1), 0, f, 0.5 * (self.height_px - 1), 0, 0, 1]

    def image_channel(self) -> str:
        return channel("IMAGE", self.name)

    def info_channel(self) -> str:
        return channel("CAMERA_INFO", self.name)

    def pixel(self, x_m: float, y_m: float, z_m: float) -> tuple[float, float]:
        """Where a map point lands in the image [px]."""
        depth = self.z_m - z_m
        return (
            0.5 * (self.width_px - 1) + self.f_px * (x_m - self.x_m) / depth,
            0.5 * (self.height_px - 1) - self.f_px * (y_m - self.y_m) / depth,
        )

    def sees(self, x_m: float, y_m: float, z_m: float, margin_px: float) -> bool:
        """The point is in the image, at least margin_px from its border."""
        u, v = self.pixel(x_m, y_m, z_m)
        return (
            margin_px <= u <= self.width_px - 1 - margin_px
            and margin_px <= v <= self.height_px - 1 - margin_px
        )

    def calibration_texts(self) -> dict[str, str]:
        """<name>_camera.yaml (intrinsics, no lens) and <name>_map.yaml (X_cam = R X_map + t:
        camera x = map x, camera y (image down) = map -y, optical axis = map -z)."""
        size = f"width_px: {self.width_px}\nheight_px: {self.height_px}\n"
        return {
            f"{self.name}_camera.yaml": f"{size}k: {self.k()}\ndist: [0, 0, 0, 0, 0]\n",
            f"{self.name}_map.yaml": f"{size}r_cam_map: [1, 0, 0, 0, -1, 0, 0, 0, -1]\n"
            f"t_cam_map_m: [{-self.x_m!r}, {self.y_m!r}, {self.z_m!r}]\n",
        }

    def write_calibration(self, folder: Path) -> tuple[Path, Path]:
        """The files of calibration_texts in folder: (intrinsics, pose)."""
        paths = []
        for name, text in self.calibration_texts().items():
            (folder / name).write_text(text)
            paths.append(folder / name)
        return paths[0], paths[1]


def sim_tag_id(car: int) -> int:
    """The roof tag id the simulator gives its car number car (1, 2, ...: mjcf_gen.c
    mjcf_gen_tag_id)."""
    return car


def kit_eye(map_name: str, maps_dir: Path = MAPS_DIR) -> OverheadCamera:
    """The overhead camera every simulator map has, "eye" (autodrive-sim --eye on EYE_IMAGE):
    the kit's, above the map's origin (mjcf.py)."""
    from autodrive.maps.loader import load_kit

    e = load_kit(maps_dir / "kit.yaml").eye_camera
    return OverheadCamera("eye", 0.0, 0.0, e.height_m, e.fovy_deg, e.width_px, e.height_px)


def config_text(
    cams: list[OverheadCamera],
    url: str,
    vehicles: list[tuple[str, int]],
    maps: dict[str, str] | None = None,
    reference_tags: str | None = None,
    extra: list[str] | None = None,
) -> str:
    """The text of an `autodrive-eye run` config serving cams as one Eye (the calibration
    files of calibration_texts beside it; maps: a camera's own map calibration file instead)."""
    lines = [f'lcm_url: "{url}"', "base_link_height_m: 0.0", *(extra or [])]
    if reference_tags is not None:
        lines.append(f"reference_tags: {reference_tags}")
    lines.append("cameras:")
    for c in cams:
        pose = (maps or {}).get(c.name, f"{c.name}_map.yaml")
        lines.append(
            f"  - {{name: {c.name}, intrinsics: {c.name}_camera.yaml, map: {pose}, "
            f"source: 'lcm:{c.image_channel()}'}}"
        )
    lines.append("vehicles:")
    lines += [f"  - {{name: {name}, tag_id: {tag}}}" for name, tag in vehicles]
    return "\n".join(lines) + "\n"


def reference_tags(map_name: str, maps_dir: Path = MAPS_DIR) -> list[dict[str, Any]]:
    """The map's reference tags (sidecar: id, x_m, y_m, z_m, yaw_rad, size_m)."""
    side = json.loads((maps_dir / f"{map_name}.json").read_text())
    tags: list[dict[str, Any]] = side.get("reference_tags", [])
    return tags


def tags_text(tags: list[dict[str, Any]]) -> str:
    """The Eye's reference tag list (calibrate-map --tags, run config reference_tags)."""
    keys = ("id", "x_m", "y_m", "z_m", "yaw_rad", "size_m")
    lines = ["tags:"] + [" - {" + ", ".join(f"{k}: {t[k]!r}" for k in keys) + "}" for t in tags]
    return "\n".join(lines) + "\n"


def load(map_name: str, maps_dir: Path = MAPS_DIR) -> list[OverheadCamera]:
    """The map's eye_cameras (empty when it has none)."""
    side = json.loads((maps_dir / f"{map_name}.json").read_text())
    return [
        OverheadCamera(
            name=c["name"],
            x_m=c["centre_m"][0],
            y_m=c["centre_m"][1],
            z_m=c["height_m"],
            fovy_deg=c["fovy_deg"],
            width_px=c["width_px"],
            height_px=c["height_px"],
        )
        for c in side.get("eye_cameras", [])
    ]


def write_eye_config(
    cams: list[OverheadCamera],
    folder: Path,
    url: str,
    vehicles: list[tuple[str, int]],
    maps: dict[str, Path] | None = None,
    reference_tags: Path | None = None,
    extra: list[str] | None = None,
) -> Path:
    """eye.yaml for `autodrive-eye run`: every camera with its lcm: source, the cars (name,
    tag id). base_link_height_m 0: the simulator's base_link is on the floor. maps: a camera's
    map calibration (calibrate-map's output, in folder) in place of the map's own pose;
    reference_tags (in folder): the tags the Eye watches for a moved camera; extra: more
    config lines."""
    for c in cams:
        c.write_calibration(folder)
    names = {k: v.name for k, v in (maps or {}).items()}
    tags = reference_tags.name if reference_tags is not None else None
    path = folder / "eye.yaml"
    path.write_text(config_text(cams, url, vehicles, names, tags, extra))
    return path
