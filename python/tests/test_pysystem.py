"""Bring-your-own Python systems go through the same trial code as the built-in ones."""

import json
import os
import sys

import numpy as np
import pytest

import verti

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "examples"))
from python_pid import PythonPid  # noqa: E402

TASKS = "1-20"


def strip(r):
    r = dict(r)
    for k in ("wall_time", "system"):
        r.pop(k)
    return r


@pytest.fixture(scope="module")
def worlds():
    return verti.load_worlds("verti-2")


def test_numpy_pid_reproduces_the_rust_pid_exactly(worlds):
    ours = verti.evaluate(PythonPid(), worlds, tasks=TASKS)
    theirs = verti.evaluate("pid", worlds, tasks=TASKS, jobs=1)
    assert len(ours) == len(theirs) == 20
    for a, b in zip(ours, theirs):
        assert a["system"] == "py-pid"
        assert (a["task"], a["outcome"], a["time"]) == (b["task"], b["outcome"], b["time"])
        # not just outcome and time: every metric, bit for bit
        assert strip(a) == strip(b)
    assert any(r["outcome"] == "success" for r in ours)


def test_results_folder_is_resumable_and_reportable(worlds, tmp_path):
    out = tmp_path / "py-pid"
    first = verti.evaluate(PythonPid(), worlds, tasks="1-5", out=str(out))
    assert len(first) == 5
    lines = (out / "results.jsonl").read_text().splitlines()
    assert [json.loads(l)["task"] for l in lines] == [1, 2, 3, 4, 5]
    # resume adds the missing tasks only
    more = verti.evaluate(PythonPid(), worlds, tasks="1-8", out=str(out), resume=True)
    assert [r["task"] for r in more] == list(range(1, 9))
    assert len((out / "results.jsonl").read_text().splitlines()) == 8
    with pytest.raises(ValueError, match="already exists"):
        verti.evaluate(PythonPid(), worlds, tasks="1-8", out=str(out))


class Recorder:
    """Checks the observation it gets and drives straight at 2 m/s (low level after 1 s)."""

    control_rate = 10.0
    state_features = ["vx", "roll", "time_left"]
    elevation = (5, 1.0)
    occupancy = (3, 2.0)

    def __init__(self):
        self.seen = []

    def reset(self, task):
        assert task["global_path"].shape[1] == 2 and task["max_time"] == 3.0
        self.task = task

    def act(self, obs):
        assert obs["state"].shape == (3,) and obs["state"].dtype == np.float32
        assert obs["elevation"].shape == (5, 5) and obs["occupancy"].shape == (3, 3)
        assert obs["pose"].shape == (6,) and obs["controls"].shape == (3,)
        assert abs(obs["state"][2] - (1.0 - obs["time"] / 3.0)) < 1e-6
        self.seen.append(obs["time"])
        return (2.0, 0.0)


def test_observation_fields_and_rate(worlds):
    rec = Recorder()
    (r,) = verti.evaluate(rec, worlds, tasks=1, max_time=3.0)
    assert r["system"] == "recorder" and r["time"] == pytest.approx(3.0)
    assert rec.seen[:3] == pytest.approx([0.0, 0.1, 0.2])


class Broken:
    def reset(self, task):
        pass

    def act(self, obs):
        raise ZeroDivisionError("boom")


def test_exceptions_propagate_and_nothing_is_recorded(worlds, tmp_path):
    out = tmp_path / "broken"
    with pytest.raises(ZeroDivisionError, match="boom"):
        verti.evaluate(Broken(), worlds, tasks="1-3", out=str(out))
    assert (out / "results.jsonl").read_text() == ""
    with pytest.raises(TypeError, match="act"):
        verti.evaluate(object(), worlds, tasks=1)
    with pytest.raises(ValueError, match="one trial at a time"):
        verti.evaluate(PythonPid(), worlds, tasks=1, jobs=2)


class WrongSize(Broken):
    def act(self, obs):
        return (1.0, 0.0, 0.0)


def test_bad_actions_are_clear_errors(worlds):
    with pytest.raises(ValueError, match="expected 2"):
        verti.evaluate(WrongSize(), worlds, tasks=1)


def test_arguments_that_used_to_mean_something_else_are_refused(worlds, tmp_path):
    # issue 10: an empty selection is not "all", resume and force exclude each other, and
    # worker counts are capped
    with pytest.raises(ValueError, match="selects no task"):
        verti.evaluate("pid", worlds, tasks=[])
    with pytest.raises(ValueError, match="pass one of them"):
        verti.evaluate("pid", worlds, tasks=1, out=str(tmp_path / "r"), resume=True, force=True)
    with pytest.raises(ValueError, match="too many"):
        verti.evaluate("pid", worlds, tasks=1, jobs=10_000)
    with pytest.raises(ValueError, match="selects nothing"):
        verti.NavigateEnv(worlds, levels=[])


def test_reset_task_must_be_a_task_number_and_save_does_not_overwrite(worlds, tmp_path):
    env = verti.NavigateEnv(worlds)
    with pytest.raises(ValueError, match="task number"):
        env.reset(options={"task": 1.5})
    obs, info = env.reset(options={"task": 2})
    assert info["task"] == 2
    path = tmp_path / "w"
    worlds[0].save(str(path))
    with pytest.raises(FileExistsError, match="overwrite=True"):
        worlds[0].save(str(path))
    worlds[0].save(str(path), overwrite=True)
    assert verti.World.load(str(path)) == worlds[0]
