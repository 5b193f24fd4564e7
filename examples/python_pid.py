"""Bring your own system: a PID path follower written in Python (numpy), evaluated by verti.

    python examples/python_pid.py [--worlds verti-100] [--tasks 1-20] [--out results/py-pid]

`verti.evaluate` accepts any object with `reset(task)` and `act(obs)`. It drives the object
through the same trial code as the built-in systems, and with `out=` writes the same resumable
`results.jsonl`, so `verti report results/py-pid results/pid-verti-100` compares it with them.

This PID mirrors the built-in `pid` operation for operation (same path follower, same
floating-point expressions), so on every task it reproduces the Rust PID's outcome and time
exactly (python/tests/test_pysystem.py checks 20 tasks).
"""

import argparse
import math

import numpy as np

import verti


class PathFollower:
    """Progress along the global path; the local goal is the first point `lookahead` away."""

    def __init__(self, path):
        self.path = np.asarray(path, dtype=np.float64).reshape(-1, 2)
        self.progress = 0

    def local_goal(self, x, y, lookahead, fallback):
        n = len(self.path)
        if n == 0:
            return fallback
        # squared distances as dx*dx + dy*dy, exactly as the Rust code computes them
        dx = self.path[:, 0] - x
        dy = self.path[:, 1] - y
        d2 = dx * dx + dy * dy
        # closest point within a forward window of 3 lookaheads of path points (first minimum)
        end = min(self.progress + 1 + math.ceil(3.0 * lookahead) * 4, n)
        self.progress += int(np.argmin(d2[self.progress:end]))
        # first point from there at least `lookahead` away, else the last point
        far = np.nonzero(d2[self.progress:] >= lookahead * lookahead)[0]
        i = self.progress + int(far[0]) if len(far) else n - 1
        return self.path[i]


def wrap_angle(a):
    """Wraps to [-pi, pi) as Rust's rem_euclid does."""
    t = math.fmod(a + math.pi, math.tau)
    if t < 0.0:
        t += math.tau
    return t - math.pi


class PythonPid:
    """Steers toward a local goal 10 m ahead on the global path at 3 m/s (the paper's PID)."""

    name = "py-pid"
    control_rate = 20.0  # Hz, like the built-in pid
    action_mode = "high"  # act returns (target speed m/s, steering in [-1, 1])

    def __init__(self, speed=3.0, lookahead=10.0, kp=1.0):
        self.speed, self.lookahead, self.kp = speed, lookahead, kp

    def reset(self, task):
        self.follower = PathFollower(task["global_path"])
        self.goal = np.asarray(task["goal"], dtype=np.float64)
        self.scale = task["world_scale"]
        self.max_steer = max(task["max_steer_angle"], 1e-3)

    def act(self, obs):
        x, y, _, _, _, yaw = obs["pose"]
        g = self.follower.local_goal(x, y, self.lookahead * self.scale, self.goal)
        error = wrap_angle(math.atan2(g[1] - y, g[0] - x) - yaw)
        # kp·e + ki·integral + kd·derivative with ki = kd = 0, as the Rust PID adds them
        angle = self.kp * error + 0.0 + 0.0
        steering = min(max(angle / self.max_steer, -1.0), 1.0)
        return (self.speed * math.sqrt(self.scale), steering)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--worlds", default="verti-100")
    ap.add_argument("--tasks", default="1-20")
    ap.add_argument("--out", default=None, help="results folder (resumable, like verti eval --out)")
    a = ap.parse_args()
    ours = verti.evaluate(PythonPid(), a.worlds, tasks=a.tasks, out=a.out, force=a.out is not None)
    theirs = verti.evaluate("pid", a.worlds, tasks=a.tasks)
    same = sum(r["outcome"] == s["outcome"] and r["time"] == s["time"] for r, s in zip(ours, theirs))
    ok = sum(r["outcome"] == "success" for r in ours)
    print(f"python pid: {ok}/{len(ours)} successes; identical to the built-in pid on {same}/{len(ours)} tasks")


if __name__ == "__main__":
    main()
