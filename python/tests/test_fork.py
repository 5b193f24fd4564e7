"""Fork safety: gymnasium's async vector env forks worker processes after the parent has
loaded worlds in parallel. Each case runs in a subprocess with a timeout, so a deadlock fails
the test instead of hanging the suite."""

import os
import select
import signal
import subprocess
import sys
import textwrap
import time

import pytest

import verti

TIMEOUT = 120


@pytest.fixture(scope="module")
def set_dir(tmp_path_factory, worlds):
    """A saved world set directory (what `verti world generate --out` writes) of two worlds."""
    d = tmp_path_factory.mktemp("fork") / "set"
    d.mkdir()
    names = []
    for w in worlds[:2]:
        name = f"world-{w.index:03d}"
        w.save(str(d / name))
        names.append(name)
    (d / "set.yaml").write_text(f"format: verti-world-set\nversion: 1\nname: fork-test\nscale: 1.0\nworlds: [{', '.join(names)}]\n")
    return str(d)


def run_script(body: str, *args: str) -> subprocess.CompletedProcess:
    """Runs `body` in a new session; on timeout the whole session (forked children included)
    is killed and the test fails."""
    p = subprocess.Popen(
        [sys.executable, "-c", textwrap.dedent(body), *args],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    try:
        out, err = p.communicate(timeout=TIMEOUT)
    except subprocess.TimeoutExpired:
        os.killpg(p.pid, signal.SIGKILL)
        p.communicate()
        pytest.fail(f"no answer in {TIMEOUT} s (a deadlock?)")
    return subprocess.CompletedProcess(p.args, p.returncode, out, err)


def test_async_vector_env_over_a_set_directory_steps(set_dir):
    # gymnasium makes one environment in the parent (loading the set with the parallel loader)
    # before it forks the workers, which load the set again
    r = run_script(
        """
        import sys, gymnasium as gym, verti
        envs = gym.make_vec("verti/Navigate-v0", num_envs=2, vectorization_mode="async", world=sys.argv[1])
        obs, info = envs.reset(seed=0)
        for _ in range(3):
            obs, rewards, term, trunc, info = envs.step(envs.action_space.sample())
        assert obs["state"].shape == (2, len(verti.STATE_FIELDS)), obs["state"].shape
        envs.close()
        print("stepped")
        """,
        set_dir,
    )
    assert r.returncode == 0 and "stepped" in r.stdout, r.stderr


def test_worlds_load_in_a_child_forked_after_a_parallel_load(set_dir):
    r = run_script(
        """
        import os, sys, verti
        assert len(verti.load_worlds(sys.argv[1])) == 2
        pid = os.fork()
        if pid == 0:
            ok = len(verti.load_worlds(sys.argv[1])) == 2 and len(verti.World.generate_set(count=2)) == 2
            os._exit(0 if ok else 1)
        _, status = os.waitpid(pid, 0)
        print("child", os.waitstatus_to_exitcode(status))
        """,
        set_dir,
    )
    assert r.returncode == 0 and "child 0" in r.stdout, r.stderr


def test_a_vector_env_made_before_a_fork_steps_in_the_child(worlds, set_dir):
    r = run_script(
        """
        import os, sys, numpy as np, verti
        env = verti.NavigateVectorEnv(2, sys.argv[1], num_threads=2)
        env.reset(seed=0)
        env.step(np.zeros((2, 2)))
        pid = os.fork()
        if pid == 0:
            env.step(np.zeros((2, 2)))
            env.reset(seed=1)
            os._exit(0)
        _, status = os.waitpid(pid, 0)
        env.step(np.zeros((2, 2)))
        print("child", os.waitstatus_to_exitcode(status))
        """,
        set_dir,
    )
    assert r.returncode == 0 and "child 0" in r.stdout, r.stderr


def _alive(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0] != "Z"
    except FileNotFoundError:
        return False


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_async_workers_exit_when_the_parent_is_killed(set_dir):
    parent = subprocess.Popen(
        [
            sys.executable,
            "-c",
            textwrap.dedent(
                """
                import sys, time, gymnasium as gym, verti
                envs = gym.make_vec("verti/Navigate-v0", num_envs=2, vectorization_mode="async", world=sys.argv[1])
                envs.reset(seed=0)
                print(" ".join(str(p.pid) for p in envs.unwrapped.processes), flush=True)
                time.sleep(600)
                """
            ),
            set_dir,
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
        start_new_session=True,
    )
    try:
        ready, _, _ = select.select([parent.stdout], [], [], TIMEOUT)
        assert ready, "the async vector env did not start"
        workers = [int(p) for p in parent.stdout.readline().split()]
        assert len(workers) == 2
        os.kill(parent.pid, signal.SIGKILL)
        parent.wait(timeout=TIMEOUT)
        deadline = time.monotonic() + 20
        while any(_alive(p) for p in workers) and time.monotonic() < deadline:
            time.sleep(0.1)
        left = [p for p in workers if _alive(p)]
        assert not left, f"workers {left} outlived their parent"
    finally:
        # the workers stay in the parent's process group after it dies: clean up everything
        try:
            os.killpg(parent.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        parent.wait(timeout=TIMEOUT)
