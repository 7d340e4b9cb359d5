"""The simulator's learning environments, registered on import under documented ids.

    import autodrive.gym, gymnasium
    env = gymnasium.make("autodrive/ParkingSchool-v0")

Gymnasium (one car; gymnasium.make):
  autodrive/DrivingSchool-v0   lane keeping on Driving School's "loop_ccw" (LaneKeepingEnv)
  autodrive/LaneKeeping-v0     lane keeping on any map and route (kwargs map_name, route)
  autodrive/ParkingSchool-v0   parking to a slot of Parking School (ParkingEnv, kwarg slot)
PettingZoo (N cars, parallel API; autodrive.gym.make_parallel(id, **kwargs)):
  autodrive/Intersection-v0        N cars on their routes (IntersectionEnv, kwarg cars)
  autodrive/MarlIntersection-v1    the intersection-traversal task of autodrive.learn.marl
                                   (MarlIntersectionEnv: action_mode, shield, shaping ...)

Underneath: worlds in process (World, step_worlds) on the C library of
sim/mujoco_hil/include/autodrive_sim_api.h (autodrive.gym.world)."""

from __future__ import annotations

import importlib
from typing import Any

import gymnasium

from autodrive.gym.world import Observation, SimError, World, step_worlds

NAMESPACE = "autodrive"

GYM_ENVS: dict[str, tuple[str, dict[str, Any]]] = {
    "autodrive/DrivingSchool-v0": (
        "autodrive.gym.envs:LaneKeepingEnv",
        {"map_name": "driving_school", "route": "loop_ccw"},
    ),
    "autodrive/LaneKeeping-v0": ("autodrive.gym.envs:LaneKeepingEnv", {}),
    "autodrive/ParkingSchool-v0": ("autodrive.gym.envs:ParkingEnv", {}),
}
PARALLEL_ENVS: dict[str, str] = {
    "autodrive/Intersection-v0": "autodrive.gym.pz_env:IntersectionEnv",
    "autodrive/MarlIntersection-v1": "autodrive.learn.marl.env:MarlIntersectionEnv",
}

for _id, (_entry, _kwargs) in GYM_ENVS.items():
    if _id not in gymnasium.registry:
        gymnasium.register(id=_id, entry_point=_entry, kwargs=_kwargs)


def make_parallel(env_id: str, **kwargs: Any) -> Any:
    """A PettingZoo parallel environment of PARALLEL_ENVS by id (PettingZoo has no registry)."""
    if env_id not in PARALLEL_ENVS:
        raise KeyError(
            f"{env_id}: not a PettingZoo environment of autodrive.gym "
            f"({', '.join(PARALLEL_ENVS)})"
        )
    module, name = PARALLEL_ENVS[env_id].split(":")
    return getattr(importlib.import_module(module), name)(**kwargs)


__all__ = [
    "GYM_ENVS",
    "PARALLEL_ENVS",
    "Observation",
    "SimError",
    "World",
    "make_parallel",
    "step_worlds",
]
