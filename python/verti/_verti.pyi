"""Type stubs of the extension module ``verti._verti`` (Rust source: crates/verti-py/src/python).

Every Rust error becomes a Python exception carrying the Rust message unchanged (``ValueError``
for bad input, ``FileNotFoundError``/``OSError`` for files, ``SimulationError`` for a blown-up
simulation); a panic becomes ``RuntimeError``. Calls that can take long release the GIL and stop
on Ctrl-C with ``KeyboardInterrupt``.

The names below that start with an underscore and are not functions (``_StrPath``,
``_TaskDict``, ...) exist only for type checkers: import them under ``typing.TYPE_CHECKING``.
"""

import os
from collections.abc import Callable, Iterable, Mapping, Sequence
from typing import Any, Literal, Protocol, TypedDict, final

import numpy as np
from numpy.typing import NDArray
from typing_extensions import Self, Unpack

__all__ = [
    "World",
    "Sim",
    "SimState",
    "EnvCore",
    "VecEnvCore",
    "load_worlds",
    "_world_from_files",
    "vehicles",
    "systems",
    "evaluate",
    "_replay",
    "_load_dataset",
    "_generate_dataset",
    "SimulationError",
    "STATE_FIELDS",
    "SIM_STATE_FIELDS",
    "FEATURES",
    "OUTCOMES",
    "__version__",
]

__version__: str

# ----------------------------------------------------------------------------------------------
# argument and result types (for type checkers only)

_StrPath = str | os.PathLike[str]
#: One parameter value of a system or an elevation source: a bool, int, float, str or path.
#: (Parameter and weight mappings are typed as ``Mapping`` so that a ``dict[str, float]`` fits;
#: at run time they must be dicts.)
_ParamValue = bool | int | float | str | os.PathLike[str]
#: Worlds: a World, several of them, or a name (``"verti-100"``, ``"verti-100:42"``, a world
#: or set directory, a folder of Verti-Bench worlds).
_WorldsArg = str | World | Iterable[World]
#: Tasks: None (all), one global task number, a list of them or a range string (``"1-10,15"``).
_TasksArg = str | int | Sequence[int] | NDArray[np.integer[Any]] | None
#: A map patch: None (off), a size in cells of 0.1 m, or (size, resolution in metres).
_CropArg = int | tuple[int, float] | None
#: A selection by name: None (all), one name or a list of names.
_NamesArg = str | Sequence[str] | None

class _TaskDict(TypedDict):
    """One start/goal pair of a world (``World.tasks``)."""

    pair: int
    task: int
    start: tuple[float, float]
    goal: tuple[float, float]
    distance: float
    path_length: float

class _ObstacleDict(TypedDict):
    """One rock or tree of a world (``World.obstacles``)."""

    kind: Literal["rock", "tree"]
    position: tuple[float, float, float]
    yaw: float
    radius: float
    z_range: tuple[float, float]
    footprint: NDArray[np.float64]

class _EnvSettings(TypedDict, total=False):
    """The keyword settings of ``EnvCore`` and ``VecEnvCore`` (None: the default)."""

    perception: str | None
    scale: float | None
    control_rate: float | None
    action_mode: str | None
    max_speed: float | None
    max_time: float | None
    rules: str | None
    lookahead: float | None
    elevation: _CropArg
    semantic: _CropArg
    occupancy: _CropArg
    reward_weights: Mapping[str, float] | None
    tasks: _TasksArg
    levels: _NamesArg
    densities: _NamesArg
    terrain_types: _NamesArg
    seed: int | None
    inner_dt: float | None
    state_features: Sequence[str] | None

class _System(Protocol):
    """A Python mobility system for ``evaluate``: ``reset(task)`` gets the task dict, ``act(obs)``
    returns (target speed m/s, steering) or, with ``action_mode = "low"``, (throttle, brake,
    steering). Optional attributes: ``name``, ``control_rate``, ``action_mode``,
    ``state_features``, ``lookahead``, ``elevation``, ``semantic``, ``occupancy``."""

    def reset(self, task: dict[str, Any], /) -> object: ...
    def act(self, obs: dict[str, Any], /) -> Sequence[float] | NDArray[Any]: ...

#: An observation dict: ``state``, ``goal``, ``local_goal`` and the requested patches.
_Obs = dict[str, NDArray[Any]]
#: An observation layout: name -> (shape, dtype name).
_Layout = dict[str, tuple[tuple[int, ...], str]]

# ----------------------------------------------------------------------------------------------
# constants

#: Names of the environment's default state vector entries.
STATE_FIELDS: list[str]
#: Names of the simulator state vector entries (``SimState.vector``, ``Sim.rollout`` columns).
SIM_STATE_FIELDS: list[str]
#: Every feature of the schema: name -> (unit, description).
FEATURES: dict[str, tuple[str, str]]
#: Trial outcome names; a vector environment's ``info["outcome"]`` indexes this list.
OUTCOMES: list[str]

class SimulationError(RuntimeError):
    """The simulation blew up: the vehicle state stopped being finite or physical."""

# ----------------------------------------------------------------------------------------------
# worlds

@final
class World:
    """One immutable world: terrain, semantics, obstacles, tasks and global paths."""

    @staticmethod
    def generate(
        seed: int = 0,
        index: int = 1,
        count: int = 100,
        scale: float = 1.0,
        elevation: str = "procedural-rock",
        elevation_params: Mapping[str, _ParamValue] | None = None,
    ) -> World:
        """World ``index`` (1-based) of the generated set (seed, count, scale); the same world as
        ``verti world generate`` writes. Generates only that world. ``elevation`` names the
        elevation source (``verti world sources``; default ``procedural-rock``, e.g.
        ``swae-v1``) and ``elevation_params`` its parameters."""

    @staticmethod
    def generate_set(
        seed: int = 0,
        count: int = 100,
        scale: float = 1.0,
        elevation: str = "procedural-rock",
        elevation_params: Mapping[str, _ParamValue] | None = None,
    ) -> list[World]:
        """Every world of a generated set, in parallel (Ctrl-C stops it); ``elevation`` and
        ``elevation_params`` as for ``generate``."""

    @staticmethod
    def load(path: _StrPath) -> World:
        """Loads a world directory (with world.yaml) written by ``verti world generate`` or
        ``save``."""

    @staticmethod
    def resolve(spec: str, scale: float | None = None) -> World:
        """A world by the command line's names: ``verti-100:42``, ``verti-20-s7:3``, a world
        directory, or ``DIR:INDEX`` of a saved set or a Verti-Bench folder. ``scale`` (default 1)
        applies to generated and imported worlds; a saved world keeps its own, and another
        ``scale`` for it is an error."""

    @staticmethod
    def import_verti_bench(
        config: _StrPath,
        heightmap: _StrPath,
        labels: _StrPath | None = None,
        scale: float = 1.0,
        index: int | None = None,
        clearance: float | None = None,
    ) -> World:
        """Imports an original Verti-Bench world from its config YAML, grey heightmap BMP and
        optional label npy."""

    def save(self, path: _StrPath, overwrite: bool = False) -> None:
        """Writes the world as a directory in verti's format. An existing directory is replaced
        only with ``overwrite=True`` (like the CLI's ``--force``); a missing parent directory is
        not created."""

    @property
    def heights(self) -> NDArray[np.float64]:
        """Vertex heights (m), ``size × size``, row 0 north, column 0 west: a read-only view of
        the world's own memory (no copy)."""

    @property
    def labels(self) -> NDArray[np.uint8]:
        """Terrain class label (Verti-Bench ids 0..9) at every vertex, ``size × size``, uint8."""

    @property
    def name(self) -> str:
        """Human-readable name, e.g. ``verti-100/042`` or ``vb/config12_high``."""

    @property
    def index(self) -> int:
        """1-based index in its set (the Verti-Bench world id for imports)."""

    @property
    def size(self) -> int:
        """Vertices per side."""

    @property
    def cell(self) -> float:
        """Metres between vertices."""

    @property
    def half_extent(self) -> float:
        """The map spans [-half_extent, half_extent] metres in x and y."""

    @property
    def scale(self) -> float:
        """Length scale relative to the full-scale (HMMWV) world."""

    @property
    def level(self) -> str:
        """Elevation level: ``low``, ``mid`` or ``high``."""

    @property
    def terrain_type(self) -> str:
        """Terrain type: ``rigid``, ``deformable`` or ``mixed``."""

    @property
    def density(self) -> str:
        """Obstacle density: ``sparse``, ``medium`` or ``dense``."""

    @property
    def max_height(self) -> float:
        """Height of grey level 255 / the level's ceiling, metres (already scaled)."""

    def height_at(self, x: float, y: float) -> float:
        """Terrain height (m) at world (x, y) on the triangulated surface."""

    @property
    def tasks(self) -> list[_TaskDict]:
        """The start/goal pairs: dicts with ``pair``, ``task`` (global number), ``start``,
        ``goal``, ``distance`` and ``path_length``."""

    def path(self, pair: int) -> NDArray[np.float64]:
        """The global path of a pair, ``k × 2`` world (x, y); empty when no path exists."""

    @property
    def obstacles(self) -> list[_ObstacleDict]:
        """Rocks and trees: dicts with ``kind``, ``position``, ``yaw``, ``radius`` (horizontal
        bounding radius), ``z_range`` and ``footprint`` (convex polygon, ``k × 2``)."""

    def render(self, pixels_per_cell: int = 4, legend: bool = True, title: bool = True) -> NDArray[np.uint8]:
        """A top view (``H × W × 3`` uint8) like ``verti world render``."""

    def __eq__(self, value: object, /) -> bool: ...
    def __ne__(self, value: object, /) -> bool: ...
    def __hash__(self) -> int:
        """Consistent with ``==``: equal worlds have equal metadata."""

    def __reduce__(self) -> tuple[Callable[[dict[str, bytes]], World], tuple[dict[str, bytes]]]:
        """Pickling (multiprocessing, SubprocVecEnv): the world travels as the bytes of its
        files in verti's format, which round-trips a world exactly."""

    def __copy__(self) -> Self:
        """Worlds are immutable: a copy is the same world."""

    def __deepcopy__(self, _memo: Any) -> Self:
        """Worlds are immutable: a copy is the same world."""

def load_worlds(spec: str = "verti-100", scale: float | None = None) -> list[World]:
    """Every world of a set given by name (``verti-100``, ``verti-20-s7``, a saved set directory,
    a world directory or a folder of Verti-Bench worlds). Ctrl-C stops generation."""

def _world_from_files(files: dict[str, bytes]) -> World:
    """Rebuilds a pickled world from the bytes of its files."""

# ----------------------------------------------------------------------------------------------
# vehicles and the simulator

def vehicles() -> list[str]:
    """Names of the built-in vehicles."""

@final
class SimState:
    """A snapshot of a vehicle's state (immutable; restore it with ``Sim.state = snapshot``)."""

    @property
    def time(self) -> float:
        """Simulated time, s."""

    @property
    def pose(self) -> tuple[float, float, float, float, float, float]:
        """Reference-frame pose (x, y, z, roll, pitch, yaw): metres and radians, Z-Y-X Euler
        angles."""

    @property
    def com_position(self) -> tuple[float, float, float]:
        """Centre-of-mass position (world), m."""

    @property
    def euler(self) -> tuple[float, float, float]:
        """(roll, pitch, yaw), rad."""

    @property
    def velocity_body(self) -> tuple[float, float, float]:
        """Linear velocity in the body frame (x forward, y left, z up), m/s."""

    @property
    def angular_velocity_body(self) -> tuple[float, float, float]:
        """Angular velocity in the body frame, rad/s."""

    @property
    def forward_speed(self) -> float:
        """Speed along the chassis x axis, m/s."""

    @property
    def rolled_over(self) -> bool:
        """True when the chassis is upside down or on its side."""

    @property
    def vector(self) -> NDArray[np.float64]:
        """The state as a float64 vector with the entries named by ``verti.SIM_STATE_FIELDS``."""

    def to_dict(self) -> dict[str, float]:
        """The state as a dict of the named entries."""

@final
class Sim:
    """One vehicle on one world. ``step`` advances it; ``state`` reads (or restores) a snapshot;
    ``clone`` gives an independent copy sharing the immutable model (cheap)."""

    def __new__(
        cls,
        world: World,
        vehicle: str = "hmmwv",
        start: int | tuple[float, float, float] | None = None,
    ) -> Self:
        """``start``: None for the world's pair 0, an int for that pair's start (facing its
        goal), or (x, y, yaw) in metres and radians. ``vehicle``: a built-in vehicle's name
        (``verti.vehicles()``) or a vehicle YAML file."""

    def step(self, throttle: float, brake: float, steering: float, dt: float = 0.01) -> None:
        """Advances by ``dt`` seconds (default 0.01, the benchmark's inner step) with the driver
        inputs held: throttle and brake in [0, 1], steering in [-1, 1] (positive = left)."""

    def rollout(self, controls: NDArray[np.float64], dt: float = 0.01) -> NDArray[np.float64]:
        """Applies each row (throttle, brake, steering) of ``controls`` (a float64 array,
        ``T × 3``) for ``dt`` seconds and returns the state after each row, ``T × 16`` (columns
        ``verti.SIM_STATE_FIELDS``). The GIL is released; a planner can roll out clones from
        several threads."""

    def reset(self) -> None:
        """Back to the start, at rest."""

    @property
    def state(self) -> SimState:
        """A snapshot of the current state; assigning one (from this Sim or a clone) restores
        it."""

    @state.setter
    def state(self, value: SimState) -> None: ...
    def clone(self) -> Sim:
        """An independent copy at the same state (shares the immutable model)."""

    def __copy__(self) -> Sim: ...
    def __deepcopy__(self, _memo: Any) -> Sim: ...
    @property
    def time(self) -> float:
        """Simulated time, s."""

    @property
    def vehicle(self) -> str:
        """The vehicle's name."""

    @property
    def world(self) -> World:
        """The world the vehicle drives on."""

    @property
    def internal_step(self) -> float:
        """The fixed internal physics step, s."""

# ----------------------------------------------------------------------------------------------
# environment cores (use verti.envs.NavigateEnv / NavigateVectorEnv)

@final
class EnvCore:
    """The Rust side of ``verti.envs.NavigateEnv``: one environment, stepped one control period
    per call. Use the gymnasium wrapper rather than this class directly."""

    def __new__(cls, worlds: _WorldsArg, vehicle: str | None = None, **settings: Unpack[_EnvSettings]) -> Self: ...
    def reset(self, seed: int | None = None, task: int | None = None) -> tuple[_Obs, dict[str, Any]]:
        """Starts an episode: returns (observation dict, info dict)."""

    def step(self, action: NDArray[np.float64]) -> tuple[_Obs, float, bool, bool, dict[str, Any]]:
        """One control period (``action``: a float64 vector, normalised): returns (observation,
        default reward, terminated, truncated, info)."""

    def render(self, pixels_per_cell: int = 4) -> NDArray[np.uint8]:
        """Top view with the task, the trail and the vehicle, ``H × W × 3`` uint8."""

    @property
    def observation_layout(self) -> _Layout:
        """Observation layout: dict of name -> (shape, dtype name)."""

    @property
    def action_dim(self) -> int:
        """2 for ``high`` actions, 3 for ``low``."""

    @property
    def action_mode(self) -> Literal["high", "low"]:
        """``high`` (target speed, steering) or ``low`` (throttle, brake, steering)."""

    @property
    def control_rate(self) -> float:
        """Actions per simulated second, Hz."""

    @property
    def task_count(self) -> int:
        """Number of tasks the sampler draws from."""

    @property
    def task_numbers(self) -> list[int]:
        """Global task numbers the sampler draws from."""

    @property
    def worlds(self) -> list[World]:
        """The environment's worlds."""

    def sim(self) -> Sim:
        """A simulator at the current state of the episode (for planning from Python)."""

@final
class VecEnvCore:
    """The Rust side of ``verti.envs.NavigateVectorEnv``: N environments stepped in parallel,
    one call per batch, with next-step autoreset."""

    def __new__(
        cls,
        num_envs: int,
        worlds: _WorldsArg,
        vehicle: str | None = None,
        num_threads: int | None = None,
        **settings: Unpack[_EnvSettings],
    ) -> Self: ...
    def reset(self, seed: int | Sequence[int] | None = None) -> tuple[_Obs, dict[str, NDArray[Any]]]:
        """Resets every environment: ``seed`` None (continue each sampler), an int (environment
        i gets seed + i, gymnasium's convention) or one seed per environment. Returns
        (observations, infos)."""

    def step(
        self, actions: NDArray[np.float64]
    ) -> tuple[_Obs, NDArray[np.float64], NDArray[np.bool_], NDArray[np.bool_], dict[str, NDArray[Any]]]:
        """Steps all environments with ``actions`` (float64, ``num_envs × action_dim``,
        normalised) in parallel with the GIL released; returns (observations, rewards,
        terminated, truncated, infos)."""

    def env_info(self, i: int) -> dict[str, Any]:
        """The info dict of one environment (as the single environment reports it)."""

    def render(self, i: int = 0, pixels_per_cell: int = 4) -> NDArray[np.uint8]:
        """Renders environment ``i``."""

    @property
    def num_envs(self) -> int:
        """Number of environments."""

    @property
    def observation_layout(self) -> _Layout:
        """Observation layout of one environment: dict of name -> (shape, dtype name)."""

    @property
    def action_dim(self) -> int:
        """2 for ``high`` actions, 3 for ``low``."""

    @property
    def action_mode(self) -> Literal["high", "low"]:
        """``high`` (target speed, steering) or ``low`` (throttle, brake, steering)."""

    @property
    def control_rate(self) -> float:
        """Actions per simulated second, Hz."""

    @property
    def task_count(self) -> int:
        """Number of tasks the sampler draws from."""

# ----------------------------------------------------------------------------------------------
# evaluation, replay and datasets

def evaluate(
    system: str | _System | None = None,
    worlds: _WorldsArg | None = None,
    tasks: _TasksArg = None,
    jobs: int | None = None,
    *,
    vehicle: str | None = None,
    params: Mapping[str, _ParamValue] | Iterable[tuple[str, _ParamValue]] | None = None,
    rules: str = "paper",
    max_time: float = 60.0,
    seed: int = 0,
    scale: float | None = None,
    start: str = "settled",
    out: _StrPath | None = None,
    resume: bool = False,
    force: bool = False,
    perception: str = "none",
) -> list[dict[str, Any]]:
    """Runs ``system`` on the selected tasks, ``jobs`` trials at a time, and returns one dict per
    trial (the fields of ``results.jsonl``), sorted by task. With ``out``, results are also
    written there, resumable like ``verti eval``. Ctrl-C stops it.

    Arguments:

    - system: a built-in system's name (default ``"pid"``; ``verti.systems()`` lists them), or
      a Python object with ``reset(task)`` and ``act(obs)``, run one trial at a time through
      the same trial code. ``act`` returns (target speed m/s, steering in [-1, 1]), or with
      ``action_mode = "low"`` (throttle, brake, steering). Optional attributes: ``name``,
      ``control_rate`` (Hz), ``action_mode``, ``state_features``, ``lookahead``,
      ``elevation``, ``semantic``, ``occupancy`` (the observation the object asks for).
    - worlds: a set by name (``"verti-100"``, the default; a saved set, a world directory or a
      folder of Verti-Bench worlds), ``"SET:INDEX"`` for one world, a World or a list of
      Worlds. A set by name builds only the worlds of the selected tasks.
    - tasks: task numbers, as ``"1-10,15"``, an int, a sequence or an array of ints; None for
      all.
    - jobs: trials run at once (default: one per core; a Python system runs one at a time).
    - vehicle: a built-in vehicle's name or a vehicle YAML file (default: the vehicle for the
      worlds' scale).
    - params: a built-in system's parameters, ``{name: value}`` or (name, value) pairs, each
      checked against its declared type and range.
    - rules: ``"paper"`` (default) or ``"verti-bench"`` (the reference code's rules).
    - max_time: seconds per trial before a timeout (default 60).
    - seed: the seed of every random draw (default 0): same seed, same results.
    - scale: the scale to build named worlds at (default 1).
    - start: ``"settled"`` (default) or ``"drop"`` (Verti-Bench's spawn above the ground).
    - out: a folder for ``results.jsonl`` and ``run.json``, created if missing (its parent must
      exist).
    - resume: continue the run in ``out``, skipping finished tasks.
    - force: discard the run in ``out`` and start over.
    - perception: ``"none"`` (default), ``"low"``, ``"medium"``, ``"high"`` or a perception
      YAML file: noise on what the system observes."""

def systems() -> list[dict[str, Any]]:
    """The systems that ``evaluate`` knows, with their parameters (name, type, default, min and
    max or choices, doc)."""

def _replay(
    run: _StrPath, task: int, out: _StrPath, worlds: _WorldsArg | None = None
) -> dict[str, Any]:
    """Re-runs task ``task`` of the run in directory ``run`` and writes its 3-D recording to
    ``out`` (``.html``: a self-contained page; ``.json``: the recording itself). ``worlds``
    replaces the world set the run names (checked by content). Returns the replayed trial's
    result dict; warns if it ended otherwise than the recorded one."""

def _load_dataset(path: _StrPath) -> tuple[dict[str, NDArray[Any] | list[str | None]], str]:
    """Loads the dataset in ``path``: (dict of column name -> numpy array, in schema order; the
    ``outcome`` column is a list of str or None) and the manifest as JSON text."""

def _generate_dataset(
    out: _StrPath,
    kind: str,
    hours: float,
    worlds: str,
    vehicle: str,
    seed: int,
    rate: float,
    profile: str,
    max_trial_seconds: float,
    force: bool,
) -> str:
    """Generates a random-exploration (or failures-from-exploration) dataset into ``out``, as
    ``verti data generate KIND --from random`` does; evaluation worlds are refused. Returns the
    manifest as JSON text."""
