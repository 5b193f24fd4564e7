"""verti: an off-road mobility benchmark with a Rust core.

The Python face of verti (a reimplementation of Verti-Bench): worlds as numpy arrays, the
vehicle simulator, parallel evaluation of mobility systems, and gymnasium environments.

>>> import verti, gymnasium as gym
>>> world = verti.World.generate(seed=0, index=1)          # world 1 of the built-in set
>>> sim = verti.Sim(world, "hmmwv", start=0)               # at the start of pair 0
>>> sim.step(throttle=0.5, brake=0.0, steering=0.1)        # 10 ms of driving
>>> env = gym.make("verti/Navigate-v0", world=world)       # registered on import
>>> results = verti.evaluate("pid", "verti-100", tasks="1-10", out="runs/pid")  # list of dicts
>>> verti.replay("runs/pid", task=3, out="task3.html")     # a 3-D page of one trial

Long calls release the GIL and stop on Ctrl-C; Rust errors arrive as ValueError,
FileNotFoundError/OSError or verti.SimulationError with the Rust message.
"""

from ._verti import (
    OUTCOMES,
    FEATURES,
    SIM_STATE_FIELDS,
    STATE_FIELDS,
    EnvCore,
    Sim,
    SimState,
    SimulationError,
    VecEnvCore,
    World,
    __version__,
    evaluate,
    load_worlds,
    systems,
    vehicles,
)
from .results import flatten_result, results_table, to_dataframe
from .envs import NavigateEnv, NavigateVectorEnv, register_envs
from . import data
from .replay import replay

register_envs()

__all__ = [
    "OUTCOMES",
    "FEATURES",
    "SIM_STATE_FIELDS",
    "STATE_FIELDS",
    "EnvCore",
    "NavigateEnv",
    "NavigateVectorEnv",
    "Sim",
    "SimState",
    "SimulationError",
    "VecEnvCore",
    "World",
    "__version__",
    "data",
    "evaluate",
    "flatten_result",
    "load_worlds",
    "register_envs",
    "replay",
    "results_table",
    "systems",
    "to_dataframe",
    "vehicles",
]
