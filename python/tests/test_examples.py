"""The examples in examples/ run (the SB3 one only compiles: torch is not installed here)."""

import os
import py_compile
import subprocess
import sys

import pytest

EXAMPLES = os.path.join(os.path.dirname(__file__), "..", "..", "examples")


def run(script, *args, cwd):
    return subprocess.run([sys.executable, os.path.join(EXAMPLES, script), *args], cwd=cwd, capture_output=True, text=True, timeout=300)


def test_random_rollout_example(tmp_path):
    r = run("random_rollout.py", "--png", str(tmp_path / "r.png"), cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert "outcome" in r.stdout and (tmp_path / "r.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_pid_pandas_example(tmp_path):
    pytest.importorskip("pandas")
    r = run("pid_eval_pandas.py", "--worlds", "verti-3", "--tasks", "1-4", "--jobs", "1", "--csv", str(tmp_path / "t.csv"), cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert "success rate by elevation level" in r.stdout and (tmp_path / "t.csv").is_file()


def test_ppo_example_compiles():
    py_compile.compile(os.path.join(EXAMPLES, "ppo_sb3.py"), doraise=True)


def test_sb3_policies_evaluate_through_the_custom_system_api(world):
    """The example's adapter drives a stand-in for an SB3 model (torch is not installed here):
    it must receive the environment's observation keys and its scaled action must be applied."""
    import importlib.util

    import numpy as np

    import verti

    spec = importlib.util.spec_from_file_location("ppo_sb3", os.path.join(EXAMPLES, "ppo_sb3.py"))
    example = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(example)

    class Model:
        seen = []

        def predict(self, obs, deterministic):
            assert deterministic and sorted(obs) == ["elevation", "goal", "local_goal", "state"]
            assert obs["elevation"].shape == (8, 8)
            self.seen.append(obs["local_goal"])
            return np.array([0.5, 2.0], dtype=np.float32), None

    model = Model()
    r = verti.evaluate(example.Sb3System(model, elevation=8), [world], tasks=[1], jobs=1, max_time=3.0)
    assert r[0]["system"] == "sb3-ppo" and len(model.seen) >= 29
    # 0.5 x 4 m/s: the vehicle moves at about 2 m/s
    assert 3.0 < r[0]["path_length"] < 7.5
