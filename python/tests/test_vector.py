"""The vector environment: batched parallel stepping, autoreset, equivalence with single envs."""

import gymnasium as gym
import numpy as np
import pytest

import verti
from verti.envs import NavigateEnv, NavigateVectorEnv


def test_vector_env_is_a_gymnasium_vector_env(worlds):
    envs = gym.make_vec("verti/Navigate-v0", num_envs=4, vectorization_mode="vector_entry_point", world=worlds)
    assert isinstance(envs.unwrapped, gym.vector.VectorEnv) and envs.num_envs == 4
    assert envs.metadata["autoreset_mode"] == gym.vector.AutoresetMode.NEXT_STEP
    obs, info = envs.reset(seed=0)
    assert obs in envs.observation_space
    assert obs["state"].shape == (4, len(verti.STATE_FIELDS)) and obs["goal"].shape == (4, 2)
    envs.action_space.seed(0)
    for _ in range(5):
        obs, rewards, term, trunc, info = envs.step(envs.action_space.sample())
        assert obs in envs.observation_space
        assert rewards.shape == (4,) and term.dtype == bool and trunc.dtype == bool
        assert info["task"].shape == (4,) and info["outcome"].dtype == np.int8
    envs.close()


def test_vector_steps_equal_single_env_steps(worlds):
    n = 3
    vec = NavigateVectorEnv(n, worlds, num_threads=2)
    singles = [NavigateEnv(worlds) for _ in range(n)]
    obs, info = vec.reset(seed=10)
    for i, env in enumerate(singles):
        o, inf = env.reset(seed=10 + i)
        assert inf["task"] == info["task"][i]
        assert np.array_equal(o["state"], obs["state"][i])
    rng = np.random.default_rng(0)
    for _ in range(40):
        actions = rng.uniform(-1, 1, (n, 2))
        obs, rewards, term, trunc, info = vec.step(actions)
        for i, env in enumerate(singles):
            o, r, te, tr, _ = env.step(actions[i])
            assert np.array_equal(o["state"], obs["state"][i]) and np.array_equal(o["goal"], obs["goal"][i])
            assert r == rewards[i] and te == term[i] and tr == trunc[i]


def test_next_step_autoreset(world):
    vec = NavigateVectorEnv(2, world, tasks=[1], max_time=1.0)
    vec.reset(seed=0)
    for k in range(10):
        _, rewards, term, trunc, info = vec.step(np.ones((2, 2)))
    assert trunc.all() and not term.any()
    assert [verti.envs.outcome_name(c) for c in info["outcome"]] == ["timeout", "timeout"]
    assert info["_outcome"].all() and (info["path_length"] > 0).all()
    assert vec.env_info(0)["metrics"]["outcome"] == "timeout"
    # codes, not names: comparing them with a name cannot silently count nothing
    assert info["outcome"].dtype == np.int8
    assert (info["outcome"] == verti.OUTCOMES.index("timeout")).all()
    with pytest.raises(TypeError, match=r"verti.OUTCOMES.index\('success'\)"):
        _ = info["outcome"] == "success"
    with pytest.raises(TypeError, match="holds codes, not names"):
        _ = info["outcome"] != "timeout"
    # the next step resets: reward 0, not done, time back to 0
    obs, rewards, term, trunc, info = vec.step(np.ones((2, 2)))
    assert (rewards == 0).all() and not term.any() and not trunc.any()
    assert (info["time"] == 0).all() and (info["outcome"] == -1).all()
    assert (obs["state"][:, verti.STATE_FIELDS.index("time_left")] == 1.0).all()


def test_vector_reset_seeds_and_errors(worlds):
    vec = NavigateVectorEnv(4, worlds)
    with pytest.raises(ValueError, match="call reset"):
        vec.step(np.zeros((4, 2)))
    a = vec.reset(seed=5)[1]["task"]
    b = vec.reset(seed=[5, 6, 7, 8])[1]["task"]
    assert np.array_equal(a, b)
    with pytest.raises(ValueError, match="expected 4 seeds"):
        vec.reset(seed=[1, 2])
    with pytest.raises(ValueError, match="expected actions for 4 environments"):
        vec.step(np.zeros((3, 2)))
    with pytest.raises(ValueError, match="environment 2: action .* non-finite"):
        vec.step(np.array([[0, 0], [0, 0], [np.nan, 0], [0, 0]], dtype=float))
    with pytest.raises(ValueError, match="num_envs must be a positive int"):
        NavigateVectorEnv(0, worlds)
    with pytest.raises(ValueError, match="num_threads must be at least 1"):
        NavigateVectorEnv(2, worlds, num_threads=0)


def test_vector_patches_render_and_custom_reward(world):
    calls = []

    def reward(obs, action, info):
        calls.append(info["task"])
        return 1.0

    vec = NavigateVectorEnv(2, world, elevation=8, occupancy=4, reward=reward, render_mode="rgb_array", render_pixels_per_cell=1)
    obs, _ = vec.reset(seed=1)
    assert obs["elevation"].shape == (2, 8, 8) and obs["occupancy"].shape == (2, 4, 4)
    _, rewards, _, _, _ = vec.step(np.zeros((2, 2)))
    assert (rewards == 1.0).all() and len(calls) == 2
    frames = vec.render()
    assert len(frames) == 2 and frames[0].shape[2] == 3
