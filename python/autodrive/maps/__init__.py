"""The map descriptions (maps/<map>.yaml and kit.yaml): the one place a map is
written. load() reads and checks one; tiles expands the road kit's tiles into lanes, stop lines
and slots; mjcf.generate, sidecar.generate and textures.generate write the simulator's MJCF
scene, the JSON sidecar for C/C++ readers and the PNG textures (tools/gen-maps runs them);
tools/map shows (show.py) and checks (tool.py) a description.

Usage::

    from autodrive import maps, vehicle
    m = maps.load("tiny_town")
    m.spawn_pose(); m.slot("lot_s2"); m.slot_goal(2, vehicle.load()); m.obstacles()
    m.lanes(); m.centre_line("x_n_e"); m.all_stop_lines(); m.lights(); m.light_conflicts()
    m.placed_signs(); m.named_routes(); m.route("loop_ccw").polyline_m; m.named_spawns()
"""

from autodrive.maps.description import MapDescription
from autodrive.maps.loader import KIT_FILE, MAPS_DIR, load, load_kit, names
from autodrive.maps.model import Lane, MapDescriptionError, ParkingSlot, Pose, Rect

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
