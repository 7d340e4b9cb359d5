"""The environments pass their libraries' own checkers (gymnasium.utils.env_checker.check_env,
pettingzoo.test.parallel_api_test), and a reset with the same seed gives the same episode."""

import warnings

import numpy as np
from gymnasium.utils.env_checker import check_env
from pettingzoo.test import parallel_api_test

from autodrive.gym.envs import LaneKeepingEnv, ParkingEnv
from autodrive.gym import tasks
from autodrive.gym.pz_env import IntersectionEnv

warnings.filterwarnings("ignore", message=".*infinity.*")  # unbounded Box: intended


def gym_episode(env: LaneKeepingEnv | ParkingEnv, seed: int) -> np.ndarray:
    obs, _ = env.reset(seed=seed)
    rows = [obs]
    for k in range(30):
        obs, reward, term, trunc, _ = env.step(np.array([0.5, 0.3 * np.sin(0.3 * k)], np.float32))
        rows.append(np.append(obs, reward))
        if term or trunc:
            break
    return np.concatenate(rows)


def test_gym() -> None:
    makers = [lambda: LaneKeepingEnv(lidar_rays=36), lambda: ParkingEnv(lidar_rays=36)]
    if tasks.map_exists(tasks.INTERSECTION_MAP):  # a named open route of the maps contract
        makers.append(lambda: LaneKeepingEnv(tasks.INTERSECTION_MAP, "north_to_east"))
    for make in makers:
        env = make()
        check_env(env, skip_render_check=True)
        a, b, c = gym_episode(env, 11), gym_episode(env, 11), gym_episode(env, 12)
        assert np.array_equal(a, b), f"{type(env).__name__}: same seed, another episode"
        assert not np.array_equal(a, c), f"{type(env).__name__}: the seed changes nothing"
        env.close()
        print(f"{type(env).__name__}: check_env passed, seeded episodes repeat")


def test_taken_slot_refused() -> None:
    try:
        ParkingEnv(slot=5)  # Parking School's slot 5 holds a parked stand-in car
    except ValueError as e:
        assert "parked car" in str(e) and "free slots" in str(e), str(e)
        print(f"ParkingEnv refuses a taken slot: {e}")
        return
    raise AssertionError("a slot with a parked car was accepted")


def test_render() -> None:
    env = LaneKeepingEnv(render_mode="rgb_array")  # the front camera, 160 x 120
    check_env(env)  # with gymnasium's render check
    env.reset(seed=0)
    img = env.render()
    assert img.shape == (120, 160, 3) and img.std() > 5.0, "blank or misshapen camera frame"
    env.close()
    print("LaneKeepingEnv rgb_array: check_env with render passed")


def test_lane_keeper() -> None:
    """The observation means what it says: steering against the offset and heading error keeps
    the car in its lane for 10 s while the reward counts the metres it made."""
    env = LaneKeepingEnv()
    obs, _ = env.reset(seed=4)
    total = 0.0
    for _ in range(200):
        steer = float(np.clip(-2.0 * obs[0] - 1.5 * obs[1], -1.0, 1.0))
        obs, reward, term, trunc, info = env.step(np.array([0.8, steer], np.float32))
        total += float(reward)
        assert not term, f"the lane keeper left its lane: {info}"
    assert total > 1.0, f"10 s of lane keeping earned only {total:.2f}"
    print(f"a hand-written lane keeper: 10 s in the lane, return {total:.2f}")


def pz_episode(env: IntersectionEnv, seed: int) -> np.ndarray:
    obs, _ = env.reset(seed=seed)
    rows = [obs[a] for a in env.possible_agents]
    for k in range(30):
        acts = {a: np.array([0.4, 0.2 * (i - 1.5)], np.float32) for i, a in enumerate(env.agents)}
        obs, rew, _, _, _ = env.step(acts)
        rows += [np.append(obs[a], rew[a]) for a in sorted(obs)]
        if not env.agents:
            break
    return np.concatenate(rows)


def test_pettingzoo() -> None:
    env = IntersectionEnv(cars=4)
    parallel_api_test(env, num_cycles=60)
    a, b = pz_episode(env, 3), pz_episode(env, 3)
    assert np.array_equal(a, b), "same seed, another multi-agent episode"
    env.close()
    print(f"IntersectionEnv on {env.map_name}: parallel_api_test passed, seeded episodes repeat")
