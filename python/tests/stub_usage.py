"""Type-checker cases for verti/_verti.pyi, checked by mypy in run_tests.sh and never run.

Correct calls must type-check and give the asserted types; each wrong call carries a
``# type: ignore[code]`` that mypy must need (``warn_unused_ignores`` is on), so a stub that
stopped catching a wrong argument name or type fails the check.
"""

from __future__ import annotations

import pathlib
from typing import Any, Dict, List, Literal, Tuple

import numpy as np
from numpy.typing import NDArray
from typing_extensions import assert_type

import verti
from verti.envs import NavigateEnv, NavigateVectorEnv


class Driver:
    """A Python system for ``verti.evaluate``."""

    name = "driver"

    def reset(self, task: Dict[str, Any]) -> None:
        pass

    def act(self, obs: Dict[str, Any]) -> Tuple[float, float]:
        return (1.0, 0.0)


def correct_calls() -> None:
    world = verti.World.generate(seed=0, index=1, elevation="swae-v1", elevation_params={"latent_scale": 0.7})
    assert_type(world, verti.World)
    assert_type(verti.World.generate_set(count=3), List[verti.World])
    assert_type(verti.World.load(pathlib.Path("w")), verti.World)
    assert_type(verti.World.resolve("verti-100:42", scale=None), verti.World)
    assert_type(verti.World.import_verti_bench("c.yaml", "h.bmp", labels=None, scale=0.5, index=3), verti.World)
    world.save("w", overwrite=True)
    assert_type(world.heights, NDArray[np.float64])
    assert_type(world.labels, NDArray[np.uint8])
    assert_type(world.render(pixels_per_cell=2, legend=False), NDArray[np.uint8])
    assert_type(world.path(0), NDArray[np.float64])
    assert_type(world.height_at(1.0, 2.0), float)
    assert_type(world.tasks[0]["task"], int)
    assert_type(world.tasks[0]["start"], Tuple[float, float])
    assert_type(world.obstacles[0]["footprint"], NDArray[np.float64])
    assert_type(world.size, int)
    assert_type(world.level, str)
    assert_type(world == world, bool)
    assert_type(verti.load_worlds("verti-20-s7", 0.5), List[verti.World])

    sim = verti.Sim(world, "artcar", start=(0.0, 1.0, 0.5))
    sim = verti.Sim(world, start=3)
    sim.step(throttle=0.5, brake=0.0, steering=0.1, dt=0.05)
    rows = sim.rollout(np.tile([1.0, 0.0, 0.0], (10, 1)), dt=0.05)
    assert_type(rows, NDArray[np.float64])
    state = sim.state
    assert_type(state, verti.SimState)
    assert_type(state.pose, Tuple[float, float, float, float, float, float])
    assert_type(state.vector, NDArray[np.float64])
    assert_type(state.to_dict(), Dict[str, float])
    sim.state = state
    assert_type(sim.clone(), verti.Sim)
    assert_type(sim.world, verti.World)

    results = verti.evaluate("pid", "verti-100", tasks="1-10", jobs=2, params={"speed": 3.0}, out=pathlib.Path("runs/pid"))
    assert_type(results, List[Dict[str, Any]])
    verti.evaluate(Driver(), [world], tasks=range(1, 5), max_time=10.0, perception="high")
    verti.evaluate("mppi", world, tasks=[1, 2], params=[("samples", 64)], resume=True)
    speeds: Dict[str, float] = {"speed": 3.0}
    verti.evaluate("pid", tasks=np.arange(1, 11), params=speeds)
    assert_type(verti.systems(), List[Dict[str, Any]])
    assert_type(verti.vehicles(), List[str])
    assert_type(verti.FEATURES, Dict[str, Tuple[str, str]])
    assert_type(verti.OUTCOMES, List[str])
    assert_type(verti.__version__, str)
    assert_type(verti.replay("runs/pid", task=3, out="t.html"), Dict[str, Any])

    core = verti.EnvCore("verti-100", None, elevation=(32, 0.25), levels=["low"], reward_weights={"success": 1.0})
    obs, info = core.reset(seed=1, task=None)
    assert_type(obs, Dict[str, NDArray[Any]])
    assert_type(core.step(np.zeros(2))[1], float)
    assert_type(core.action_mode, Literal["high", "low"])
    assert_type(core.sim(), verti.Sim)
    vec = verti.VecEnvCore(4, [world], num_threads=2, tasks="1-10", seed=3)
    vec.reset(seed=[1, 2, 3, 4])
    assert_type(vec.step(np.zeros((4, 2)))[2], NDArray[np.bool_])
    assert_type(vec.render(1, pixels_per_cell=2), NDArray[np.uint8])

    env = NavigateEnv("verti-100:1", task=1, elevation=64)
    NavigateVectorEnv(8, [world], num_threads=2, semantic=(16, 0.5))
    assert_type(env.sim(), verti.Sim)


def wrong_calls() -> None:
    world = verti.World.generate(seed=0)
    verti.World.generate(seed=0, idx=1)  # type: ignore[call-arg]
    verti.World.generate(seed="0")  # type: ignore[arg-type]
    verti.World.load(3)  # type: ignore[arg-type]
    world.save("w", force=True)  # type: ignore[call-arg]
    world.render(pixel_per_cell=2)  # type: ignore[call-arg]
    world.height_at(1.0)  # type: ignore[call-arg]
    world.tasks[0]["number"]  # type: ignore[typeddict-item]
    world.index = 3  # type: ignore[misc]
    verti.load_worlds("verti-100", scale="1")  # type: ignore[arg-type]

    verti.Sim(world, vehicel="hmmwv")  # type: ignore[call-arg]
    verti.Sim("verti-100:1")  # type: ignore[arg-type]
    verti.Sim(world, start="pair 0")  # type: ignore[arg-type]
    sim = verti.Sim(world)
    sim.step(0.5, 0.0)  # type: ignore[call-arg]
    sim.step(throttle=0.5, brake=0.0, steer=0.1)  # type: ignore[call-arg]
    sim.rollout([[1.0, 0.0, 0.0]])  # type: ignore[arg-type]
    sim.state = sim  # type: ignore[assignment]
    sim.time = 1.0  # type: ignore[misc]

    verti.evaluate("pid", "verti-100", task="1-10")  # type: ignore[call-arg]
    verti.evaluate("pid", "verti-100", tasks=1.5)  # type: ignore[arg-type]
    verti.evaluate("pid", "verti-100", None, None, "hmmwv")  # type: ignore[call-arg]
    verti.evaluate("pid", jobs="2")  # type: ignore[arg-type]
    verti.evaluate("pid", resume="yes")  # type: ignore[arg-type]
    verti.evaluate(object())  # type: ignore[arg-type]
    verti.evaluate("pid", worlds=3)  # type: ignore[arg-type]
    verti.evaluate("pid", params={"speed": [3.0]})  # type: ignore[arg-type]

    verti.EnvCore("verti-100", levls=["low"])  # type: ignore[call-arg]
    verti.EnvCore("verti-100", elevation="64")  # type: ignore[arg-type]
    verti.VecEnvCore(4)  # type: ignore[call-arg]
    core = verti.EnvCore("verti-100")
    core.reset(seed="1")  # type: ignore[arg-type]
    core.render(i=0)  # type: ignore[call-arg]
    NavigateEnv("verti-100", levels=3)  # type: ignore[arg-type]
    verti.replay("runs/pid", 3)  # type: ignore[call-arg]
