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
