"""The generated files kept in the tree (readable without a build, and needed by PlatformIO,
which builds the firmware without Python): each one's path and its rendered text."""

from __future__ import annotations

from pathlib import Path

from autodrive.core import channels, vehicle
from autodrive.ros import topics as ros_topics
from autodrive.devtools.codegen import (
    channels_doc,
    eye_configs,
    firmware_header,
    maps_doc,
    protocol_doc,
    vehicle_doc,
)

PARAMS = "vehicle/nigel.params"
CHANNELS = "lcm_types/channels.yaml"


def render_all(root: Path) -> dict[str, str]:
    """Repository-relative path -> the text it must hold."""
    car = vehicle.load(root / PARAMS)
    table = channels.load(root / CHANNELS)
    return {
        channels_doc.PATH: channels_doc.render(table, CHANNELS),
        ros_topics.PATH: ros_topics.render(table, CHANNELS),
        vehicle_doc.PATH: vehicle_doc.render(car, PARAMS),
        firmware_header.PATH: firmware_header.render(car, PARAMS),
        protocol_doc.PATH: protocol_doc.render(root),
        maps_doc.PATH: maps_doc.render(root),
        **eye_configs.render(root),
    }
