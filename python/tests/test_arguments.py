"""Arguments at the Python boundary: typed system parameters are checked by the same code as
the command line's `--param` text, and outputs are never written into directories that a typo
would create."""

import math

import pytest

import verti
from verti.envs import NavigateEnv


@pytest.mark.parametrize(
    "value, error, message",
    [
        (2.5, ValueError, "system mppi parameter samples: `2.5` is not an integer"),
        (math.nan, ValueError, "system mppi parameter samples: `NaN` is not an integer"),
        (1e300, ValueError, r"system mppi parameter samples: 1e300 is outside \[1, 65536\]"),
        (10**30, ValueError, r"system mppi parameter samples: 1e30 is outside \[1, 65536\]"),
        (10**400, ValueError, "parameter samples: the integer 1000.* \\(401 digits\\) is outside the 64-bit range"),
        ("abc", ValueError, "system mppi parameter samples: expected int, got `abc`"),
        (True, ValueError, "system mppi parameter samples: expected int, got `true`"),
        ([1], TypeError, "parameter samples: a value of type list is not a parameter value"),
    ],
)
def test_int_parameters_refuse_what_is_not_an_integer(world, value, error, message):
    with pytest.raises(error, match=message):
        verti.evaluate("mppi", [world], tasks=[1], params={"samples": value})


def test_float_parameters_refuse_non_finite_numbers(world):
    with pytest.raises(ValueError, match="system pid parameter speed: `inf` is not a finite number"):
        verti.evaluate("pid", [world], tasks=[1], params={"speed": math.inf})


def test_an_exact_integer_as_a_float_is_an_int(world):
    (r,) = verti.evaluate("mppi", [world], tasks=[1], jobs=1, max_time=0.2, params={"samples": 2.0, "horizon": 3})
    assert r["task"] == 1


def test_a_parameter_given_twice_is_refused(world):
    with pytest.raises(ValueError, match="system pid parameter speed is given twice"):
        verti.evaluate("pid", [world], tasks=[1], params=[("speed", 3.0), ("speed", 4.0)])


def test_outputs_are_not_written_into_missing_directories(world, tmp_path):
    missing = tmp_path / "typo"
    with pytest.raises(FileNotFoundError, match=f"directory {missing} does not exist"):
        world.save(str(missing / "w"))
    with pytest.raises(FileNotFoundError, match=f"directory {missing} does not exist"):
        verti.evaluate("pid", [world], tasks=[1], max_time=0.2, out=str(missing / "run"))
    assert not missing.exists()
    world.save(str(tmp_path / "w"))  # a new directory inside an existing one is fine
    assert (tmp_path / "w" / "world.yaml").is_file()


def test_render_resolution_takes_exact_integers_only(world):
    with pytest.raises(ValueError, match="render_pixels_per_cell must be a positive int, not 2.5"):
        NavigateEnv(world, render_pixels_per_cell=2.5)
    env = NavigateEnv(world, render_mode="rgb_array", render_pixels_per_cell=2.0)
    env.reset(seed=0)
    assert env.render().shape[2] == 3


def test_a_saved_set_keeps_its_scale_and_picks_its_vehicle(tmp_path):
    # the command line's rule: --scale for a saved set must match it, and the default vehicle
    # follows the worlds' scale
    small = verti.World.generate_set(seed=3, count=1, scale=1 / 6)
    small[0].save(str(tmp_path / "w"))
    with pytest.raises(ValueError, match="does not apply .* saved at scale 1/6"):
        verti.World.resolve(str(tmp_path / "w"), scale=0.1)
    with pytest.raises(ValueError, match="does not apply"):
        verti.evaluate("pid", [small[0]], tasks=[1], max_time=1.0, scale=1.0)
    (r,) = verti.evaluate("pid", str(tmp_path / "w"), tasks=[1], max_time=1.0)
    assert r["vehicle"] == "artcar"
    with pytest.warns(UserWarning, match="vehicle hmmwv is built for scale 1 but the worlds are at scale 1/6"):
        verti.evaluate("pid", [small[0]], tasks=[1], max_time=1.0, vehicle="hmmwv")


def test_start_is_settled_or_drop(world):
    (settled,) = verti.evaluate("pid", [world], tasks=[1], max_time=2.0)
    (dropped,) = verti.evaluate("pid", [world], tasks=[1], max_time=2.0, start="drop")
    assert settled["path_length"] != dropped["path_length"]
    with pytest.raises(ValueError, match='unknown start "fly"'):
        verti.evaluate("pid", [world], tasks=[1], start="fly")
