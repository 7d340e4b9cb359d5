"""marl.env: the paper's intersection environment passes PettingZoo's own checker
(parallel_api_test) in its discrete and continuous forms, the same seed gives the same
episode, the reward follows the paper's terms (and the progress shaping is the distance gained), and the shield and the rule-based baseline
bring four cars across without a collision on one development seed on which the lane follower
without the shield collides."""

import math
import warnings

import numpy as np
from pettingzoo.test import parallel_api_test

from autodrive.learn.marl.baseline import FcfsBaseline
from autodrive.learn.marl.env import (
    COLLISION_FACTOR,
    PROGRESS_GAIN,
    SHAPING,
    SHAPING_EPS_M,
    MarlIntersectionEnv,
    follow_steering,
)

# a development seed (autodrive.core.seeds): without the shield the lane follower collides on
# it, with the shield every car arrives
SHIELD_SEED = 1_000_000_000


def test_api() -> None:
    for mode in ("discrete", "continuous"):
        env = MarlIntersectionEnv(cars=2, action_mode=mode)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            parallel_api_test(env, num_cycles=40)
        env.close()
    print("parallel_api_test passed (discrete, continuous)")


def test_seeded_and_reward() -> None:
    env = MarlIntersectionEnv(cars=4, shaping="paper")
    runs = []
    for _ in range(2):
        obs, _ = env.reset(seed=7)
        trace = [np.stack(list(obs.values()))]
        rewards = []
        for _ in range(15):
            obs, rew, _, _, _ = env.step({a: 2 for a in env.agents})
            trace.append(np.stack(list(obs.values())))
            rewards.append(rew)
        runs.append((env.stats["routes"], np.concatenate(trace)))
    assert runs[0][0] == runs[1][0], "same seed, other routes"
    assert np.array_equal(runs[0][1], runs[1][1]), "same seed, another episode"
    # shaping while driving: 0.01 / (0.001 + distance to the goal)
    for i, a in enumerate(env.possible_agents):
        if a in rewards[-1]:
            d = env._goal_distance(i)
            assert math.isclose(rewards[-1][a], SHAPING / (SHAPING_EPS_M + d), rel_tol=1e-9)
    other = env.reset(seed=8)[0]
    assert env.stats["routes"] != runs[0][0] or not np.array_equal(
        np.stack(list(other.values())), runs[0][1][:4]
    ), "another seed, the same episode"
    env.close()
    print("seeded episodes repeat; shaping reward as the paper's")


def test_progress_shaping() -> None:
    # the default shaping: PROGRESS_GAIN x the distance gained towards the goal this step, so
    # a car that stands earns nothing (the paper's term would pay it every step)
    env = MarlIntersectionEnv(cars=1)
    env.reset(seed=7)
    d0 = env._goal_distance(0)
    total = 0.0
    for _ in range(15):
        _, rew, _, _, _ = env.step({"nigel1": 1})
        total += rew["nigel1"]
    gained = d0 - env._goal_distance(0)
    assert gained > 0.1, f"the car gained only {gained:.3f} m in 1.5 s"
    assert math.isclose(total, PROGRESS_GAIN * gained, rel_tol=1e-9), (total, gained)
    env.close()
    try:
        MarlIntersectionEnv(cars=1, shaping="bogus")
    except ValueError as e:
        assert "bogus" in str(e)
    else:
        raise AssertionError("an unknown shaping was accepted")
    print(f"progress shaping: {total:.3f} for {gained:.3f} m gained")


def test_steer_rate_penalty() -> None:
    # continuous mode: the reward loses steer_rate_penalty x |steering change| each step (the
    # progress term is the same with either penalty: same seed, same actions)
    totals = {}
    for penalty in (0.0, 0.5):
        env = MarlIntersectionEnv(cars=1, action_mode="continuous", steer_rate_penalty=penalty)
        env.reset(seed=7)
        total = 0.0
        for k in range(10):
            _, rew, _, _, _ = env.step({"nigel1": np.array([0.4 if k % 2 else -0.4], np.float32)})
            total += rew["nigel1"]
        totals[penalty] = total
        env.close()
    # steering -0.4 from 0, then nine changes of 0.8: 7.6 units of change
    assert math.isclose(totals[0.0] - totals[0.5], 0.5 * 7.6, rel_tol=1e-6), totals
    try:
        MarlIntersectionEnv(cars=1, steer_rate_penalty=-1.0)
    except ValueError as e:
        assert "steer_rate_penalty" in str(e)
    else:
        raise AssertionError("a negative steering-rate penalty was accepted")
    print(f"steering-rate penalty: {totals}")


def run(env: MarlIntersectionEnv, seed: int) -> dict:
    env.reset(seed=seed)
    while env.agents:
        acts = {}
        for a in env.agents:
            k = env.possible_agents.index(a)
            s = follow_steering(env.cars_now[k], env.waypoint(k))
            acts[a] = int(np.clip(round(s), -1, 1)) + 1
        _, rew, term, _, info = env.step(acts)
        for a in term:
            if info[a]["outcome"] == "collision":
                k = env.possible_agents.index(a)
                assert math.isclose(rew[a], -COLLISION_FACTOR * env._goal_distance(k))
    return env.stats


def test_shield_and_baseline() -> None:
    # a lane follower on discrete steering, one seed: without the shield, cars collide; with
    # it, every car arrives and none collides
    without = run(MarlIntersectionEnv(cars=4, shield=False, max_steps=500), SHIELD_SEED)
    assert "collision" in without["outcome"], without["outcome"]
    with_shield = run(MarlIntersectionEnv(cars=4, shield=True, max_steps=500), SHIELD_SEED)
    assert with_shield["outcome"] == ["goal"] * 4, with_shield["outcome"]
    assert with_shield["shield_interventions"] > 0
    env = MarlIntersectionEnv(cars=4, max_steps=500)
    env.baseline = FcfsBaseline()
    env.reset(seed=SHIELD_SEED)
    while env.agents:
        env.step({})
    assert env.stats["outcome"] == ["goal"] * 4, env.stats["outcome"]
    print(
        f"shield: all at goal ({with_shield['shield_interventions']} interventions); without: "
        f"{without['outcome']}; baseline: all at goal"
    )
