"""The learning API of the simulator: worlds in process (World, step_worlds), Gymnasium
environments of one car (LaneKeepingEnv, ParkingEnv) and a PettingZoo parallel environment of
N cars (IntersectionEnv). The C library: sim/mujoco_hil/include/autodrive_sim_api.h."""

from autodrive.gym.world import Observation, SimError, World, step_worlds

__all__ = ["Observation", "SimError", "World", "step_worlds"]
