"""maps/ -> eye/config/maps/<map>/: a ready `autodrive-eye run` config for every camera of every
simulator map, generated from the map (autodrive.maps.eye_cameras): eye.yaml for the kit's
overhead camera "eye" (autodrive-sim --eye, EYE_IMAGE) on a map without eye_cameras, and on a
map with them (Tiny Town) <cam>.yaml for each one alone and eye_cameras.yaml for all of them as
one Eye, with each
camera's <cam>_camera.yaml and <cam>_map.yaml (the map's own pose: the simulator's truth;
calibrate-map gives a measured one). The simulator's cars wear tag i on NIGEL<i>."""

from __future__ import annotations

from pathlib import Path

from autodrive.core import channels
from autodrive.maps import eye_cameras
from autodrive.maps.loader import names

FOLDER = "eye/config/maps"
CARS = 4  # the cars the configs list (NIGEL1..NIGEL4, tag ids 1..4)


def render(root: Path) -> dict[str, str]:
    """Repository-relative path -> text, for every map in root/maps."""
    maps_dir = root / "maps"
    table = channels.load(root / "lcm_types" / "channels.yaml")
    cars = [(channels.vehicle_name(i), eye_cameras.sim_tag_id(i)) for i in range(1, CARS + 1)]
    out: dict[str, str] = {}
    for name in names(maps_dir):
        folder = f"{FOLDER}/{name}"
        head = f"# Generated from maps/{name}.yaml by tools/gen-docs: do not edit.\n"
        # autodrive-sim --eye renders a map's eye_cameras if it has them, else the kit's "eye"
        own = eye_cameras.load(name, maps_dir)
        cams = own or [eye_cameras.kit_eye(name, maps_dir)]
        for cam in cams:
            for file, text in cam.calibration_texts().items():
                out[f"{folder}/{file}"] = head + text
            single = "eye.yaml" if cam.name == "eye" else f"{cam.name}.yaml"
            out[f"{folder}/{single}"] = head + eye_cameras.config_text(
                [cam], table.url_default, cars
            )
        tags = eye_cameras.reference_tags(name, maps_dir)
        if tags:  # calibrate-map --tags: the prints the simulator lays on this map's floor
            out[f"{folder}/reference_tags.yaml"] = head + eye_cameras.tags_text(tags)
        if own:
            out[f"{folder}/eye_cameras.yaml"] = head + eye_cameras.config_text(
                own, table.url_default, cars
            )
    return out
