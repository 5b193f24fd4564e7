"""Environment throughput: ``python -m verti.bench``.

Measures env steps per second (each step = one control period, 0.1 s of simulated driving at
the default 10 Hz) for the single environment driven from a Python loop and for the vector
environment (one Rust call per batch, rayon, GIL released), on the rigid worlds of the
built-in set with no map patches. Episodes reset as they end (autoreset), and that time is
included. The policy is ``--policy random`` (uniform actions: half of them brake) or
``forward`` (full target speed, random steering).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import time

import numpy as np

import verti
from verti.envs import NavigateEnv, NavigateVectorEnv


def _actions(rng, policy, shape):
    a = rng.uniform(-1.0, 1.0, shape)
    if policy == "forward":
        a[..., 0] = 1.0
    return a


def bench_single(worlds, seconds, policy, vehicle, seed=0):
    env = NavigateEnv(worlds, vehicle=vehicle, terrain_types=["rigid"])
    rng = np.random.default_rng(seed)
    env.reset(seed=seed)
    steps, episodes = 0, 0
    t0 = time.perf_counter()
    while time.perf_counter() - t0 < seconds:
        for _ in range(100):
            _, _, term, trunc, _ = env.step(_actions(rng, policy, 2))
            steps += 1
            if term or trunc:
                env.reset()
                episodes += 1
    dt = time.perf_counter() - t0
    return {"mode": "single", "threads": 1, "envs": 1, "steps": steps, "episodes": episodes, "seconds": dt, "steps_per_s": steps / dt}


def bench_vector(worlds, seconds, policy, vehicle, num_envs, threads, seed=0):
    env = NavigateVectorEnv(num_envs, worlds, vehicle=vehicle, num_threads=threads, terrain_types=["rigid"])
    rng = np.random.default_rng(seed)
    env.reset(seed=seed)
    env.step(_actions(rng, policy, (num_envs, 2)))  # warm the thread pool
    steps, episodes = 0, 0
    t0 = time.perf_counter()
    while time.perf_counter() - t0 < seconds:
        _, _, term, trunc, _ = env.step(_actions(rng, policy, (num_envs, 2)))
        steps += num_envs
        episodes += int(term.sum() + trunc.sum())
    dt = time.perf_counter() - t0
    return {
        "mode": "vector",
        "threads": threads,
        "envs": num_envs,
        "steps": steps,
        "episodes": episodes,
        "seconds": dt,
        "steps_per_s": steps / dt,
        "steps_per_s_per_thread": steps / dt / threads,
    }


def main(argv=None):
    p = argparse.ArgumentParser(prog="python -m verti.bench", description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--seconds", type=float, default=5.0, help="wall seconds per measurement (default 5)")
    p.add_argument("--envs", type=int, default=64, help="environments in the vector env (default 64)")
    p.add_argument("--threads", type=int, nargs="*", default=None, help="worker threads to try (default: 1 and all cores)")
    p.add_argument("--policy", choices=["random", "forward"], default="random")
    p.add_argument("--vehicle", default="hmmwv")
    p.add_argument("--worlds", default="verti-100", help="world set (its rigid worlds are used)")
    p.add_argument("--json", action="store_true", help="print JSON instead of a table")
    args = p.parse_args(argv)

    cores = os.cpu_count() or 1
    threads = args.threads or sorted({1, cores})
    t0 = time.perf_counter()
    worlds = [w for w in verti.load_worlds(args.worlds) if w.terrain_type == "rigid"]
    if not worlds:
        p.error(f"{args.worlds} has no rigid world")
    setup = time.perf_counter() - t0
    rows = [bench_single(worlds, args.seconds, args.policy, args.vehicle)]
    for t in threads:
        rows.append(bench_vector(worlds, args.seconds, args.policy, args.vehicle, args.envs, t))
    info = {
        "verti": verti.__version__,
        "python": platform.python_version(),
        "cpu_count": cores,
        "worlds": f"{len(worlds)} rigid worlds of {args.worlds}",
        "vehicle": args.vehicle,
        "policy": args.policy,
        "control_rate_hz": 10,
        "world_setup_s": round(setup, 2),
    }
    if args.json:
        print(json.dumps({"setup": info, "results": rows}, indent=2))
        return
    print(
        f"verti {info['verti']}, Python {info['python']}, {cores} cores; {info['worlds']}, {args.vehicle}, "
        f"policy {args.policy}, 10 Hz control (one step = 0.1 s simulated), no map patches"
    )
    print(f"{'mode':8} {'threads':>7} {'envs':>5} {'steps':>9} {'episodes':>8} {'steps/s':>10} {'steps/s/thread':>15}")
    for r in rows:
        per = r.get("steps_per_s_per_thread", r["steps_per_s"])
        print(f"{r['mode']:8} {r['threads']:>7} {r['envs']:>5} {r['steps']:>9} {r['episodes']:>8} {r['steps_per_s']:>10.0f} {per:>15.0f}")


if __name__ == "__main__":
    main()
