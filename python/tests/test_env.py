"""The gymnasium environment: checker, determinism, rules, rewards, options, errors."""

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import verti
from verti.envs import NavigateEnv


# the checker warns about the unbounded (infinite) Box limits of the float observations
CHECKER_BOUNDS = "ignore:.*Box observation space (minimum|maximum) value is"


@pytest.mark.filterwarnings(CHECKER_BOUNDS)
def test_registered_and_passes_the_env_checker(world):
    assert "verti/Navigate-v0" in gym.registry
    env = gym.make("verti/Navigate-v0", world=world, render_mode="rgb_array")
    check_env(env.unwrapped, skip_render_check=False)
    env.close()


@pytest.mark.filterwarnings(CHECKER_BOUNDS)
@pytest.mark.filterwarnings("ignore:.*Not able to test alternative render modes")
def test_checker_passes_with_patches_and_low_level_actions(world):
    env = NavigateEnv(world, action_mode="low", elevation=16, semantic=(8, 0.5), occupancy=(8, 1.0))
    check_env(env)
    obs, _ = env.reset(seed=0)
    assert obs["elevation"].shape == (16, 16) and obs["elevation"].dtype == np.float32
    assert obs["semantic"].shape == (8, 8) and obs["semantic"].dtype == np.uint8
    assert obs["occupancy"].shape == (8, 8) and set(np.unique(obs["occupancy"])) <= {0, 1}
    # the elevation patch is relative to the ground under the vehicle: ~0 at the centre
    assert abs(float(obs["elevation"][8, 8])) < 0.5
    assert env.action_space.shape == (3,)


def test_observation_layout_and_goal_in_body_frame(world):
    env = NavigateEnv(world, task=1)
    obs, info = env.reset(seed=3)
    assert set(obs) == {"state", "goal", "local_goal"}
    assert obs["state"].shape == (len(verti.STATE_FIELDS),) and obs["state"].dtype == np.float32
    assert info["task"] == 1 and info["world"] == 1 and info["pair"] == 0 and info["outcome"] is None
    # the vehicle starts facing its goal, 120 m away: the goal is straight ahead
    gx, gy = obs["goal"]
    assert gx == pytest.approx(info["distance_to_goal"], rel=0.02) and abs(gy) < 3.0
    assert 100.0 < info["distance_to_goal"] < 125.0
    s = dict(zip(verti.STATE_FIELDS, obs["state"]))
    assert s["time_left"] == 1.0 and abs(s["vx"]) < 0.5


def test_reset_seed_is_reproducible_and_samples_tasks(worlds):
    env = NavigateEnv(worlds)
    assert len(env.task_numbers) == 40

    def rollout(seed):
        obs, info = env.reset(seed=seed)
        tasks, states = [info["task"]], [obs["state"].copy()]
        rng = np.random.default_rng(seed)
        for _ in range(30):
            obs, r, term, trunc, info = env.step(rng.uniform(-1, 1, 2))
            states.append(obs["state"].copy())
            if term or trunc:
                obs, info = env.reset()
                tasks.append(info["task"])
        for _ in range(5):
            tasks.append(env.reset()[1]["task"])
        return tasks, np.array(states)

    t1, s1 = rollout(11)
    t2, s2 = rollout(11)
    assert t1 == t2 and np.array_equal(s1, s2)
    samples = {rollout(s)[0][0] for s in range(12)}
    assert len(samples) > 3, samples


def test_task_filters_and_fixed_task(worlds):
    levels = {w.index: w.level for w in worlds}
    level = levels[1]
    env = NavigateEnv(worlds, levels=[level])
    expected = [t for w in worlds if w.level == level for t in range(10 * w.index - 9, 10 * w.index + 1)]
    assert sorted(env.task_numbers) == expected
    for seed in range(8):
        assert levels[env.reset(seed=seed)[1]["world"]] == level
    env = NavigateEnv(worlds, tasks="11-13")
    assert {env.reset(seed=s)[1]["task"] for s in range(20)} <= {11, 12, 13}
    env = NavigateEnv(worlds, task=25)
    assert env.reset(seed=1)[1]["task"] == 25
    assert env.reset(options={"task": 7})[1]["task"] == 7


def test_driving_toward_the_goal_earns_progress_reward(world):
    env = NavigateEnv(world, task=1)
    obs, info = env.reset(seed=0)
    x0, y0 = info["pose"][:2]
    total_progress = 0.0
    for _ in range(50):  # 5 s at full target speed, steering toward the local goal
        lx, ly = obs["local_goal"]
        obs, reward, term, trunc, info = env.step(np.array([1.0, np.clip(np.arctan2(ly, lx) / 0.53, -1, 1)]))
        terms = info["reward_terms"]
        assert reward == pytest.approx(sum(terms.values()))
        total_progress += terms["progress"]
        assert not (term or trunc)
    assert info["time"] == pytest.approx(5.0)
    # 50 per metre of planar progress toward the local goal, which lies ahead on the path
    moved = float(np.hypot(info["pose"][0] - x0, info["pose"][1] - y0))
    assert moved > 5.0
    assert 0.7 * 50.0 * moved < total_progress < 1.3 * 50.0 * moved
    # a custom reward replaces it; the default stays in the info
    env = NavigateEnv(world, task=1, reward=lambda obs, action, info: -info["distance_to_goal"])
    env.reset(seed=0)
    _, reward, _, _, info = env.step([1.0, 0.0])
    assert reward == -info["distance_to_goal"] and "default_reward" in info
    env = NavigateEnv(world, task=1, reward={"progress": 0.0, "no_progress_penalty": 0.0})
    env.reset(seed=0)
    assert env.step([1.0, 0.0])[1] == 0.0


def test_episodes_end_like_benchmark_trials(world):
    # braking in place is stuck after 10 s (paper rule): terminated, with metrics
    env = NavigateEnv(world, task=1)
    env.reset(seed=0)
    steps = 0
    while True:
        _, reward, term, trunc, info = env.step([-1.0, 0.0])
        steps += 1
        if term or trunc:
            break
    assert term and not trunc and info["outcome"] == "stuck"
    assert steps == pytest.approx(100, abs=2) and info["time"] == pytest.approx(steps * 0.1)
    assert info["metrics"]["outcome"] == "stuck" and info["metrics"]["path_length"] < 1.0
    assert info["reward_terms"]["terminal"] == -300.0
    with pytest.raises(ValueError, match="episode has ended"):
        env.step([0.0, 0.0])
    # the time limit truncates
    env = NavigateEnv(world, task=1, max_time=2.0)
    env.reset(seed=0)
    for _ in range(20):
        _, _, term, trunc, info = env.step([1.0, 0.0])
    assert trunc and not term and info["outcome"] == "timeout"


def test_pid_like_policy_matches_the_benchmark(world):
    """Steering toward the local goal at 3 m/s through the env gives PID's trial result
    when acting at PID's 20 Hz (the rules are the benchmark's own, step by step)."""
    results = verti.evaluate("pid", [world], tasks=[3], jobs=1, max_time=20.0)
    env = NavigateEnv(world, task=3, control_rate=20.0, max_speed=3.0, max_time=20.0)
    obs, info = env.reset(seed=0)
    # PID: steering = heading error to the local goal / the road-wheel angle at full lock (30° here)
    while True:
        lx, ly = obs["local_goal"]
        err = np.arctan2(ly, lx)
        obs, _, term, trunc, info = env.step([1.0, np.clip(err / np.radians(30.0), -1, 1)])
        if term or trunc:
            break
    r = results[0]
    assert info["outcome"] == r["outcome"]
    # same controller structure, float32 observations: close, not bit-identical
    assert info["metrics"]["path_length"] == pytest.approx(r["path_length"], rel=0.05)


def test_render_draws_the_trail(world):
    env = NavigateEnv(world, task=1, render_mode="rgb_array", render_pixels_per_cell=2)
    env.reset(seed=0)
    first = env.render()
    assert first.dtype == np.uint8 and first.ndim == 3 and first.shape[2] == 3
    for _ in range(30):
        env.step([1.0, 0.3])
    later = env.render()
    assert later.shape == first.shape and (later != first).any()
    with pytest.warns(UserWarning, match="without render_mode"):
        assert NavigateEnv(world).render() is None


def test_bad_arguments_raise_clear_errors(world):
    with pytest.raises(ValueError, match="unknown action_mode `fast`"):
        NavigateEnv(world, action_mode="fast")
    with pytest.raises(ValueError, match="whole number of inner steps"):
        NavigateEnv(world, control_rate=7.0)
    with pytest.raises(ValueError, match="unknown level `extreme`; known: low, mid, high"):
        NavigateEnv(world, levels=["extreme"])
    with pytest.raises(ValueError, match="no task of the 1 world"):
        NavigateEnv(world, densities=[d for d in ("sparse", "medium", "dense") if d != world.density][:1])
    with pytest.raises(ValueError, match="unknown reward weight `speed`"):
        NavigateEnv(world, reward={"speed": 1.0})
    with pytest.raises(TypeError, match="reward must be"):
        NavigateEnv(world, reward=3)
    with pytest.raises(ValueError, match="size 0 must be in 1..=512"):
        NavigateEnv(world, elevation=0)
    with pytest.raises(ValueError, match="unknown vehicle"):
        NavigateEnv(world, vehicle="bicycle")
    with pytest.raises(ValueError, match="render_mode"):
        NavigateEnv(world, render_mode="human")
    with pytest.raises(ValueError, match="task must be"):
        NavigateEnv(world, task=0)
    env = NavigateEnv(world)
    with pytest.raises(ValueError, match="call reset"):
        env.step([0.0, 0.0])
    env.reset(seed=0)
    with pytest.raises(ValueError, match="expected an action of 2 numbers"):
        env.step([0.0, 0.0, 0.0])
    with pytest.raises(ValueError, match="non-finite"):
        env.step([np.nan, 0.0])
    with pytest.raises(ValueError, match="not in this world set"):
        env.reset(options={"task": 99})
    with pytest.raises(ValueError, match="unknown reset options"):
        env.reset(options={"level": "low"})


def test_sim_of_the_episode_is_a_copy(world):
    env = NavigateEnv(world, task=1)
    env.reset(seed=0)
    env.step([1.0, 0.0])
    sim = env.sim()
    t = sim.time
    sim.step(1.0, 0.0, 0.0, dt=1.0)
    assert sim.time == pytest.approx(t + 1.0)
    assert env.sim().time == pytest.approx(t)


def test_world_names_are_resolved_once_per_process():
    a = NavigateEnv("verti-100:2", task=11)
    b = NavigateEnv("verti-100:2", task=11)
    assert a.worlds[0] is b.worlds[0] or a.worlds[0] == b.worlds[0]
    assert a.reset(seed=0)[1]["world_name"] == "verti-100/002"
    with pytest.raises(ValueError, match="unknown world set"):
        NavigateEnv("no-such-set")
