"""Every environment autodrive.gym registers can be made by its id, reset and stepped once:
the Gymnasium ids through gymnasium.make (after `import autodrive.gym` only), the PettingZoo
ids through autodrive.gym.make_parallel."""

import gymnasium

import autodrive.gym


def test_gymnasium_ids() -> None:
    ids = [i for i in gymnasium.registry if i.startswith(autodrive.gym.NAMESPACE + "/")]
    assert sorted(ids) == sorted(autodrive.gym.GYM_ENVS), ids
    for env_id in ids:
        env = gymnasium.make(env_id)
        obs, _ = env.reset(seed=1)
        assert env.observation_space.contains(obs), f"{env_id}: reset outside its space"
        env.action_space.seed(1)
        obs, reward, terminated, truncated, _ = env.step(env.action_space.sample())
        assert env.observation_space.contains(obs), f"{env_id}: step outside its space"
        assert isinstance(float(reward), float) and not terminated, (env_id, reward)
        env.close()
        print(f"{env_id}: made, reset and stepped")


def test_pettingzoo_ids() -> None:
    for env_id in autodrive.gym.PARALLEL_ENVS:
        env = autodrive.gym.make_parallel(env_id)
        obs, _ = env.reset(seed=1)
        assert set(obs) == set(env.agents), env_id
        actions = {a: env.action_space(a).sample() for a in env.agents}
        obs, rewards, _, _, _ = env.step(actions)
        assert set(rewards) <= set(env.possible_agents), env_id
        env.close()
        print(f"{env_id}: made, reset and stepped ({len(env.possible_agents)} agents)")


def test_unknown_id_named() -> None:
    try:
        autodrive.gym.make_parallel("autodrive/NoSuch-v0")
    except KeyError as e:
        assert "autodrive/NoSuch-v0" in str(e) and "Intersection" in str(e), e
    else:
        raise AssertionError("an unknown id was made")
