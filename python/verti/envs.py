"""gymnasium environments: drive a vehicle to the goal of a verti task.

* ``NavigateEnv`` (registered as ``verti/Navigate-v0``): one vehicle, one task per episode.
* ``NavigateVectorEnv`` (the registration's ``vector_entry_point``, a
  ``gymnasium.vector.VectorEnv``): N environments stepped in Rust in parallel, one call per
  batch with the GIL released, next-step autoreset.

Each step holds the action for one control period (0.1 s at the default 10 Hz) and runs the
benchmark's own inner loop inside it (speed controller and termination rules every 10 ms), so
episodes end exactly as benchmark trials do: ``terminated`` on success, stuck, rollover or a
simulation error; ``truncated`` at the time limit. ``info["outcome"]`` names the outcome and
``info["metrics"]`` carries the trial record when an episode ends (the same dict as a line of
results.jsonl, and as `verti.evaluate` returns).

Observation (a ``Dict``):

* ``state`` (13, float32): body-frame velocity (vx, vy, vz) m/s, body angular velocity
  (wx, wy, wz) rad/s, roll, pitch (rad), sin/cos of yaw, last steering, last throttle - brake,
  and the fraction of the time limit left (names in ``verti.STATE_FIELDS``);
* ``goal`` (2, float32): the goal in the body frame (x ahead, y left), metres;
* ``local_goal`` (2, float32): the global path's point a lookahead (10 m, scaled) ahead;
* optional heading-aligned patches, off by default: ``elevation`` (float32, terrain height
  relative to the ground under the vehicle), ``semantic`` (uint8 class ids 0..9) and
  ``occupancy`` (uint8, 1 = obstacle or off the map); row 0 is ahead, column 0 to the left.
  Ask for them with ``elevation=64`` (64 x 64 cells of 0.1 m) or ``elevation=(32, 0.25)``.

Action (``Box``): by default ``action_mode="high"``, (target speed, steering) in [-1, 1]^2,
speed scaled by ``max_speed`` (full-scale m/s, times sqrt(world scale)); negative speeds brake.
``action_mode="low"`` gives (throttle, brake, steering) in [0, 1] x [0, 1] x [-1, 1].
Actions are clipped to the box.

Reward: by default the reference RL reward of Verti-Bench with its z-target bug fixed (see
``verti.envs.DEFAULT_REWARD`` and the README): progress toward the local goal measured in the
plane, a no-progress penalty, roll and pitch penalties beyond 30 degrees, and a bonus or
penalty by outcome. Pass ``reward={"progress": 10.0, ...}`` to change its weights, or a
callable ``reward(obs, action, info) -> float`` to replace it (``info["default_reward"]`` and
``info["reward_terms"]`` hold the default and its parts).

Processes: ``gym.make_vec(..., vectorization_mode="async")`` forks worker processes after the
parent has made one environment (and so loaded its worlds in parallel). verti's parallel work
runs on thread pools made for each call, never on a pool shared across calls, so a forked
worker loads worlds and steps normally; a ``NavigateVectorEnv`` carried into a forked child
starts new threads there. Between commands the workers wait on their pipe to the parent, so
they exit when the parent dies, even when it is killed with SIGKILL.
"""

from __future__ import annotations

import os
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from gymnasium.vector import VectorEnv
from gymnasium.vector.utils import batch_space

from ._verti import OUTCOMES, EnvCore, Sim, VecEnvCore, World, load_worlds

ENV_ID = "verti/Navigate-v0"

#: Weights of the default reward (override any of them with ``reward={...}``).
DEFAULT_REWARD: Dict[str, float] = {
    "progress": 50.0,  # per metre of planar progress toward the local goal
    "no_progress_penalty": 10.0,  # per step slower than no_progress_speed toward it
    "no_progress_speed": 2.0,  # full-scale m/s (times sqrt(scale))
    "roll_weight": 20.0,  # -w * (|roll| / threshold) * (|roll| - threshold), radians
    "pitch_weight": 20.0,
    "tilt_threshold_deg": 30.0,
    "success": 3000.0,
    "timeout": -100.0,
    "timeout_per_metre": -10.0,  # times the distance left to the goal
    "stuck": -300.0,
    "rollover": -300.0,
    "error": -600.0,
}

WorldsArg = Union[str, World, Sequence[World]]
#: A heading-aligned map patch: None (off), a size in cells of 0.1 m, or (size, resolution_m).
CropArg = Union[None, int, Tuple[int, float]]
RewardArg = Union[None, Dict[str, float], Callable[[Dict[str, np.ndarray], np.ndarray, Dict[str, Any]], float]]


# Worlds by built-in name, shared by every environment of this process: worlds are immutable,
# and generating verti-100 takes about two seconds, which gym.make_vec(..., "sync") would
# otherwise pay once per environment. Directories are not cached (their files may change).
_WORLD_CACHE: Dict[Tuple[str, Optional[float]], List[World]] = {}


def _resolve_worlds(world: WorldsArg, scale: Optional[float]) -> WorldsArg:
    if not isinstance(world, str):
        return world
    base, _, index = world.rpartition(":")
    single = bool(base) and index.isdigit()
    if os.path.exists(base if single else world):
        return world
    key = (world, None if scale is None else float(scale))
    if key not in _WORLD_CACHE:
        _WORLD_CACHE[key] = [World.resolve(world, scale)] if single else load_worlds(world, scale)
    return _WORLD_CACHE[key]


def _count_arg(name: str, value: Any) -> int:
    """A positive int argument; 2.0 is taken as 2, while 2.5 or True is refused rather than
    truncated (the same rule as integer parameters of systems)."""
    if isinstance(value, (bool, np.bool_)):
        raise ValueError(f"{name} must be a positive int, not {value!r}")
    if isinstance(value, (float, np.floating)) and float(value).is_integer():
        value = int(value)
    if not isinstance(value, (int, np.integer)) or value < 1:
        raise ValueError(f"{name} must be a positive int, not {value!r}")
    return int(value)


def _settings(
    *,
    tasks: Union[None, str, int, Sequence[int]],
    levels: Union[None, str, Sequence[str]],
    densities: Union[None, str, Sequence[str]],
    terrain_types: Union[None, str, Sequence[str]],
    scale: Optional[float],
    control_rate: float,
    action_mode: str,
    max_speed: float,
    max_time: float,
    rules: str,
    lookahead: float,
    elevation: CropArg,
    semantic: CropArg,
    occupancy: CropArg,
    reward: RewardArg,
    state_features: Optional[Sequence[str]] = None,
    perception: Optional[str] = None,
) -> Dict[str, Any]:
    weights = reward if isinstance(reward, dict) else None
    if reward is not None and weights is None and not callable(reward):
        raise TypeError("reward must be None, a dict of default-reward weights or a callable(obs, action, info) -> float")
    return dict(
        tasks=tasks,
        levels=levels,
        densities=densities,
        terrain_types=terrain_types,
        scale=scale,
        control_rate=control_rate,
        action_mode=action_mode,
        max_speed=max_speed,
        max_time=max_time,
        rules=rules,
        lookahead=lookahead,
        elevation=elevation,
        semantic=semantic,
        occupancy=occupancy,
        reward_weights=weights,
        state_features=None if state_features is None else list(state_features),
        perception=None if perception is None else str(perception),
    )


def _observation_space(layout: Dict[str, Any]) -> spaces.Dict:
    parts: Dict[str, spaces.Space[Any]] = {}
    for name, (shape, dtype) in layout.items():
        if dtype == "float32":
            parts[name] = spaces.Box(-np.inf, np.inf, shape=tuple(shape), dtype=np.float32)
        elif name == "semantic":
            parts[name] = spaces.Box(0, 9, shape=tuple(shape), dtype=np.uint8)
        else:
            parts[name] = spaces.Box(0, 1, shape=tuple(shape), dtype=np.uint8)
    return spaces.Dict(parts)


def _action_space(mode: str) -> spaces.Box:
    if mode == "high":
        return spaces.Box(-1.0, 1.0, shape=(2,), dtype=np.float32)
    return spaces.Box(np.array([0.0, 0.0, -1.0], np.float32), np.array([1.0, 1.0, 1.0], np.float32), dtype=np.float32)


class NavigateEnv(gym.Env):
    """Drive from a task's start to its goal (see the module docstring).

    Args:
        world: a ``World``, a list of them, or a name: ``"verti-100"`` (the built-in set),
            ``"verti-100:42"`` (one world of it), a world or set directory, or a folder of
            Verti-Bench worlds.
        task: a global task number (world 1 pair 0 is 1, world 100 pair 9 is 1000) to run
            every episode; default: sample from the tasks selected by the filters below.
        vehicle: built-in vehicle name (``verti.vehicles()``) or a vehicle YAML file (default:
            the one for the worlds' scale: hmmwv, artcar at 1/6, verti4 at 1/10).
        tasks: task numbers to sample from (list or range string such as ``"1-50"``).
        levels, densities, terrain_types: keep only worlds of these elevation levels
            (low/mid/high), obstacle densities (sparse/medium/dense) and terrain types
            (rigid/deformable/mixed) in the sampler, e.g. for a curriculum.
        scale: world scale used when ``world`` names a generated or imported set (default 1);
            saved worlds keep theirs, and another scale for them is an error.
        control_rate: actions per simulated second (10 Hz: each step is 0.1 s).
        action_mode: ``"high"`` (target speed, steering) or ``"low"`` (throttle, brake, steering).
        max_speed: full-scale m/s of a high-level speed action of 1.
        max_time: time limit, simulated seconds (truncation).
        rules: ``"paper"`` (default) or ``"verti-bench"`` (the reference code's rules).
        lookahead: local goal distance along the global path, full-scale metres.
        elevation, semantic, occupancy: heading-aligned patches (None = off).
        reward: None (default reward), a dict of its weights, or a callable.
        state_features: names of the state vector's entries (default ``verti.STATE_FIELDS``;
            every feature with its unit is in ``verti.FEATURES``).
        perception: perception noise on what the agent observes (never on the physics):
            None or ``"none"`` (ground truth), ``"low"``, ``"medium"``, ``"high"``, or a YAML file.
        render_mode: None or ``"rgb_array"`` (top view with the task, trail and vehicle).
        render_pixels_per_cell: render resolution (4 gives 516 x 516 for a full world).
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 10}

    def __init__(
        self,
        world: WorldsArg = "verti-100",
        task: Optional[int] = None,
        vehicle: Optional[str] = None,
        *,
        tasks: Union[None, str, Sequence[int]] = None,
        levels: Union[None, str, Sequence[str]] = None,
        densities: Union[None, str, Sequence[str]] = None,
        terrain_types: Union[None, str, Sequence[str]] = None,
        scale: Optional[float] = None,
        control_rate: float = 10.0,
        action_mode: str = "high",
        max_speed: float = 4.0,
        max_time: float = 60.0,
        rules: str = "paper",
        lookahead: float = 10.0,
        elevation: CropArg = None,
        semantic: CropArg = None,
        occupancy: CropArg = None,
        reward: RewardArg = None,
        state_features: Optional[Sequence[str]] = None,
        perception: Optional[str] = None,
        render_mode: Optional[str] = None,
        render_pixels_per_cell: int = 4,
    ):
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"render_mode must be None or 'rgb_array', not {render_mode!r}")
        settings = _settings(
            tasks=tasks,
            levels=levels,
            densities=densities,
            terrain_types=terrain_types,
            scale=scale,
            control_rate=control_rate,
            action_mode=action_mode,
            max_speed=max_speed,
            max_time=max_time,
            rules=rules,
            lookahead=lookahead,
            elevation=elevation,
            semantic=semantic,
            occupancy=occupancy,
            reward=reward,
            state_features=state_features,
            perception=perception,
        )
        self._core = EnvCore(_resolve_worlds(world, scale), vehicle, **settings)
        self._reward_fn = reward if callable(reward) else None
        if task is not None and (isinstance(task, bool) or not isinstance(task, (int, np.integer)) or task < 1):
            raise ValueError(f"task must be a task number >= 1, not {task!r}")
        self._task = None if task is None else int(task)
        self._sampler_seeded = False
        self.render_mode = render_mode
        self._pixels_per_cell = _count_arg("render_pixels_per_cell", render_pixels_per_cell)
        self.observation_space = _observation_space(self._core.observation_layout)
        self.action_space = _action_space(self._core.action_mode)
        self.metadata = dict(self.metadata, render_fps=int(round(self._core.control_rate)))

    def reset(
        self, *, seed: Optional[int] = None, options: Optional[Dict[str, Any]] = None
    ) -> Tuple[Dict[str, np.ndarray], Dict[str, Any]]:
        super().reset(seed=seed)
        options = options or {}
        unknown = set(options) - {"task"}
        if unknown:
            raise ValueError(f"unknown reset options {sorted(unknown)}; known: 'task'")
        task = options.get("task", self._task)
        if task is not None and (isinstance(task, bool) or not isinstance(task, (int, np.integer)) or task < 1):
            raise ValueError(f"options['task'] must be a task number >= 1, not {task!r}")
        if seed is not None:
            core_seed = int(seed)
        elif not self._sampler_seeded:
            # first reset without a seed: draw one from gymnasium's entropy-seeded generator
            core_seed = int(self.np_random.integers(0, 2**63 - 1))
        else:
            core_seed = None  # continue the task sampler
        self._sampler_seeded = True
        return self._core.reset(seed=core_seed, task=None if task is None else int(task))

    def step(self, action):
        a = np.asarray(action, dtype=np.float64).reshape(-1)
        obs, reward, terminated, truncated, info = self._core.step(a)
        if self._reward_fn is not None:
            reward = float(self._reward_fn(obs, np.asarray(action), info))
        return obs, float(reward), bool(terminated), bool(truncated), info

    def render(self):
        if self.render_mode is None:
            gym.logger.warn("render() called without render_mode; create the environment with render_mode='rgb_array'")
            return None
        return self._core.render(self._pixels_per_cell)

    def sim(self) -> Sim:
        """A ``verti.Sim`` at the current state (a copy: stepping it leaves the episode alone)."""
        return self._core.sim()

    @property
    def task_numbers(self) -> List[int]:
        """Global task numbers the sampler draws from."""
        return self._core.task_numbers

    @property
    def worlds(self) -> List[World]:
        return self._core.worlds


class NavigateVectorEnv(VectorEnv):
    """``num_envs`` navigation environments stepped in parallel in Rust.

    Takes the arguments of ``NavigateEnv`` (except ``task``, use ``tasks``) plus ``num_envs``
    and ``num_threads`` (worker threads, default: all cores). Autoreset is next-step
    (gymnasium's default): the step after an environment ends resets it, ignores its action
    and reports reward 0, terminated and truncated False for it. ``info`` holds arrays over
    environments (``task``, ``time``, ``distance_to_goal``, ``default_reward``, ``outcome`` as
    an index into ``verti.OUTCOMES`` or -1 while running, with its mask ``_outcome``, and the
    metrics ``path_length``, ``roll_mean_abs``, ``pitch_mean_abs`` of ended episodes).
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 10, "autoreset_mode": gym.vector.AutoresetMode.NEXT_STEP}

    def __init__(
        self,
        num_envs: int = 8,
        world: WorldsArg = "verti-100",
        vehicle: Optional[str] = None,
        *,
        num_threads: Optional[int] = None,
        tasks: Union[None, str, Sequence[int]] = None,
        levels: Union[None, str, Sequence[str]] = None,
        densities: Union[None, str, Sequence[str]] = None,
        terrain_types: Union[None, str, Sequence[str]] = None,
        scale: Optional[float] = None,
        control_rate: float = 10.0,
        action_mode: str = "high",
        max_speed: float = 4.0,
        max_time: float = 60.0,
        rules: str = "paper",
        lookahead: float = 10.0,
        elevation: CropArg = None,
        semantic: CropArg = None,
        occupancy: CropArg = None,
        reward: RewardArg = None,
        state_features: Optional[Sequence[str]] = None,
        perception: Optional[str] = None,
        render_mode: Optional[str] = None,
        render_pixels_per_cell: int = 4,
    ):
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"render_mode must be None or 'rgb_array', not {render_mode!r}")
        num_envs = _count_arg("num_envs", num_envs)
        settings = _settings(
            tasks=tasks,
            levels=levels,
            densities=densities,
            terrain_types=terrain_types,
            scale=scale,
            control_rate=control_rate,
            action_mode=action_mode,
            max_speed=max_speed,
            max_time=max_time,
            rules=rules,
            lookahead=lookahead,
            elevation=elevation,
            semantic=semantic,
            occupancy=occupancy,
            reward=reward,
            state_features=state_features,
            perception=perception,
        )
        self._core = VecEnvCore(int(num_envs), _resolve_worlds(world, scale), vehicle, num_threads, **settings)
        self._reward_fn = reward if callable(reward) else None
        self._sampler_seeded = False
        self.num_envs = int(num_envs)
        self.render_mode = render_mode
        self._pixels_per_cell = _count_arg("render_pixels_per_cell", render_pixels_per_cell)
        self.single_observation_space = _observation_space(self._core.observation_layout)
        self.single_action_space = _action_space(self._core.action_mode)
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self.metadata = dict(self.metadata, render_fps=int(round(self._core.control_rate)))

    def reset(
        self, *, seed: Union[None, int, Sequence[int]] = None, options: Optional[Dict[str, Any]] = None
    ) -> Tuple[Dict[str, np.ndarray], Dict[str, Any]]:
        if options:
            raise ValueError(f"unknown reset options {sorted(options)}; the vector environment takes none")
        core_seed: Union[None, int, Sequence[int]]
        if isinstance(seed, (int, np.integer)):
            self._np_random, self._np_random_seed = gym.utils.seeding.np_random(int(seed))
            core_seed = int(seed)
        elif seed is None and not self._sampler_seeded:
            core_seed = [int(s) for s in self.np_random.integers(0, 2**63 - 1, size=self.num_envs)]
        else:
            core_seed = seed
        self._sampler_seeded = True
        obs, info = self._core.reset(seed=core_seed)
        if "outcome" in info:
            info["outcome"] = np.asarray(info["outcome"]).view(OutcomeCodes)
        return obs, info

    def step(self, actions):
        a = np.asarray(actions, dtype=np.float64)
        if a.ndim == 1:
            a = a.reshape(self.num_envs, -1) if a.size % self.num_envs == 0 else a.reshape(1, -1)
        obs, rewards, terminated, truncated, info = self._core.step(a)
        info["outcome"] = np.asarray(info["outcome"]).view(OutcomeCodes)
        if self._reward_fn is not None:
            # slow path: the callable sees one environment at a time
            rewards = np.array(
                [
                    float(self._reward_fn({k: v[i] for k, v in obs.items()}, np.asarray(actions)[i], self._core.env_info(i)))
                    for i in range(self.num_envs)
                ]
            )
        return obs, rewards, terminated, truncated, info

    def render(self):
        if self.render_mode is None:
            gym.logger.warn("render() called without render_mode; create the environment with render_mode='rgb_array'")
            return None
        return tuple(self._core.render(i, self._pixels_per_cell) for i in range(self.num_envs))

    def env_info(self, i: int) -> Dict[str, Any]:
        """The single-environment info dict of environment ``i`` (outcome name, metrics, ...)."""
        return self._core.env_info(i)


class OutcomeCodes(np.ndarray):
    """The vector environment's ``info["outcome"]``: int8 indices into ``verti.OUTCOMES``, -1
    while running. The single environment names its outcome, so ``info["outcome"] == "success"``
    would silently match nothing here; comparing these codes with a string raises instead,
    saying what to compare with (``verti.OUTCOMES.index("success")``, or ``outcome_name``)."""

    def _refuse(self, other: object) -> None:
        if isinstance(other, str):
            raise TypeError(
                f'info["outcome"] of the vector environment holds codes, not names: compare with '
                f"verti.OUTCOMES.index({other!r}) (or map codes through verti.envs.outcome_name)"
            )

    def __eq__(self, other: object) -> Any:
        self._refuse(other)
        return np.ndarray.__eq__(self, other)

    def __ne__(self, other: object) -> Any:
        self._refuse(other)
        return np.ndarray.__ne__(self, other)


def outcome_name(code: int) -> Optional[str]:
    """Name of a vectorised outcome code (-1 = still running)."""
    return None if code < 0 else OUTCOMES[code]


def register_envs() -> None:
    """Registers ``verti/Navigate-v0`` with gymnasium (done on ``import verti``)."""
    if ENV_ID not in gym.registry:
        gym.register(
            id=ENV_ID,
            entry_point="verti.envs:NavigateEnv",
            vector_entry_point="verti.envs:NavigateVectorEnv",
        )
