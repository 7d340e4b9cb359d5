"""The map descriptions (sim/mujoco_hil/maps/<map>.yaml and kit.yaml): the one place a map is
written. load() reads and checks one; mjcf.generate and sidecar.generate write the simulator's
MJCF scene and the JSON sidecar for C/C++ readers (tools/gen-maps runs both).

Usage::

    from autodrive_tools import maps, vehicle
    m = maps.load("parking_school")
    m.spawn_pose(); m.slot(2); m.slot_goal(2, vehicle.load()); m.obstacles()
    m.lanes(); m.centre_line("x_east"); m.stop_lines; m.traffic_lights; m.signs
"""

from .description import MapDescription
from .loader import KIT_FILE, MAPS_DIR, load, load_kit, names
from .model import Lane, MapDescriptionError, ParkingSlot, Pose, Rect

__all__ = [
    "KIT_FILE",
    "MAPS_DIR",
    "Lane",
    "MapDescription",
    "MapDescriptionError",
    "ParkingSlot",
    "Pose",
    "Rect",
    "load",
    "load_kit",
    "names",
]
