"""The MARL evaluation's scoring (learn/marl/evaluate.tally_episode on the env's outcomes) is
shown to catch what it scores, on real batch-simulator episodes with planted faults on one
development seed: a car steered off the road is an off-road car and a failed episode; cars held
past the step limit are timeouts; a lane follower without the shield collides, with it on the
same seed every car arrives. Each counted fault fails the episode."""

import numpy as np

from autodrive.core import seeds
from autodrive.learn.marl.env import MarlIntersectionEnv, follow_steering
from autodrive.learn.marl.evaluate import new_tally, tally_episode

SEED = seeds.DEVELOPMENT.start  # traced before: development, never a reported figure


def episode(env: MarlIntersectionEnv, act) -> dict:
    env.reset(seed=SEED)
    while env.agents:
        env.step({a: act(env, a) for a in env.agents})
    acc = new_tally()
    tally_episode(acc, SEED, env.stats)
    return acc


def follow(env: MarlIntersectionEnv, a: str) -> int:
    k = env.possible_agents.index(a)
    return int(np.clip(round(follow_steering(env.cars_now[k], env.waypoint(k))), -1, 1)) + 1


def test_an_off_road_car_is_counted() -> None:
    def veer(env, a):  # nigel1 steers full left all the way; the others follow their lanes
        return 0 if a == "nigel1" else follow(env, a)

    acc = episode(MarlIntersectionEnv(cars=1, shield=False, max_steps=500), veer)
    assert acc["off_road"] == 1 and acc["successes"] == 0, acc
    assert acc["failed_seeds"] == [SEED]


def test_a_timeout_is_counted() -> None:
    acc = episode(MarlIntersectionEnv(cars=4, shield=True, max_steps=20), follow)  # 2 s
    assert acc["timeouts"] == 4 and acc["successes"] == 0, acc


def test_the_shield_prevents_the_collision_on_one_seed() -> None:
    without = episode(MarlIntersectionEnv(cars=4, shield=False, max_steps=500), follow)
    assert without["collisions"] > 0 and without["successes"] == 0, without
    shielded = episode(MarlIntersectionEnv(cars=4, shield=True, max_steps=500), follow)
    assert shielded["collisions"] == 0 and shielded["successes"] == 1, shielded
    assert shielded["shield_interventions"] > 0
