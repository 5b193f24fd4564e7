"""Train a PPO policy on verti/Navigate-v0 with Stable-Baselines3 (not run in CI).

    pip install "stable-baselines3>=2.3"     # pulls torch: several GB with its CUDA wheels
    python examples/ppo_sb3.py --timesteps 200000 --envs 8

What it does:
* a training curriculum over the built-in set: low-elevation, sparse-obstacle worlds first
  (``--levels low --densities sparse``), then widen the filters in later runs;
* the default reward (the reference Verti-Bench RL reward with its z-target bug fixed) and the
  default observation (state vector + goal + local goal in the body frame; add
  ``--elevation 32`` for a 32 x 32 heading-aligned elevation patch, which switches the policy
  to SB3's MultiInputPolicy with a flattening extractor);
* SB3's own ``SubprocVecEnv``/``DummyVecEnv`` over single environments (SB3 does not take
  gymnasium VectorEnvs); the worlds are generated once and passed to every environment
  (worlds pickle exactly, so ``--subproc`` ships them to the worker processes);
* PPO hyperparameters of the reference's shipped policies (spec §6.4: n_steps 400 per env,
  batch 200, 10 epochs, lr 5e-4, gamma 0.99, GAE 0.95, clip 0.2);
* training on ``verti-100-s1`` (never the evaluation set), then evaluation of the deterministic
  policy on verti-100 through the custom-system API (``Sb3System``: ``verti.evaluate`` encodes
  its observations exactly as the environment did, so the policy sees what it trained on), with
  the same ``results.jsonl`` as the built-in systems (``--results DIR`` for ``verti report``).

verti's own PPO (``verti learn rl``) ships the ``rl``, ``mcl`` and ``acl`` policies; from
Python they run as ``verti.evaluate("rl", "verti-100")``.
"""

import argparse
from collections import Counter

import gymnasium as gym
import numpy as np

import verti  # noqa: F401  (registers verti/Navigate-v0)


def make_env(args, worlds, tasks=None, seed=0):
    def thunk():
        env = gym.make(
            "verti/Navigate-v0",
            world=worlds,
            levels=args.levels,
            densities=args.densities,
            terrain_types=args.terrain_types,
            tasks=tasks,
            elevation=args.elevation,
        )
        env.reset(seed=seed)
        return env

    return thunk


class Sb3System:
    """A trained SB3 policy as a verti system: the environment's observation settings as
    attributes, ``model.predict`` on the observation dict, the normalised action scaled as the
    environment scales it (speed x max_speed x sqrt(world scale), steering as is)."""

    name = "sb3-ppo"
    control_rate = 10.0  # the environment's control rate
    action_mode = "high"

    def __init__(self, model, elevation=None, max_speed=4.0):
        self.model = model
        self.elevation = (elevation, 0.1) if elevation else None
        self.max_speed = max_speed
        self.scale = 1.0

    def reset(self, task):
        self.scale = task["world_scale"]

    def act(self, obs):
        keys = ["state", "goal", "local_goal"] + (["elevation"] if self.elevation else [])
        action, _ = self.model.predict({k: obs[k] for k in keys}, deterministic=True)
        speed, steering = np.clip(action, -1.0, 1.0)
        return float(speed) * self.max_speed * self.scale**0.5, float(steering)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--worlds", default="verti-100-s1", help="training worlds (never verti-100)")
    p.add_argument("--levels", nargs="*", default=["low"])
    p.add_argument("--densities", nargs="*", default=["sparse"])
    p.add_argument("--terrain-types", nargs="*", default=None)
    p.add_argument("--elevation", type=int, default=None, help="size of an elevation patch (cells of 0.1 m)")
    p.add_argument("--timesteps", type=int, default=200_000)
    p.add_argument("--envs", type=int, default=8)
    p.add_argument("--subproc", action="store_true", help="one process per environment")
    p.add_argument("--eval-tasks", default="1-1000", help="verti-100 tasks of the final evaluation")
    p.add_argument("--results", default=None, help="write the evaluation's results.jsonl here")
    p.add_argument("--out", default="ppo_verti")
    args = p.parse_args()

    from stable_baselines3 import PPO
    from stable_baselines3.common.vec_env import DummyVecEnv, SubprocVecEnv

    worlds = verti.load_worlds(args.worlds)
    vec_cls = SubprocVecEnv if args.subproc else DummyVecEnv
    train = vec_cls([make_env(args, worlds, seed=i) for i in range(args.envs)])
    policy = "MultiInputPolicy"  # Dict observations
    model = PPO(
        policy,
        train,
        n_steps=400,
        batch_size=200,
        n_epochs=10,
        learning_rate=5e-4,
        gamma=0.99,
        gae_lambda=0.95,
        clip_range=0.2,
        ent_coef=0.0,
        vf_coef=0.5,
        max_grad_norm=0.5,
        policy_kwargs=dict(net_arch=dict(pi=[64, 64], vf=[64, 64])),
        verbose=1,
    )
    model.learn(total_timesteps=args.timesteps)
    model.save(args.out)
    print(f"saved {args.out}.zip")

    # evaluation on verti-100 through the custom-system API, with the benchmark's outcomes
    results = verti.evaluate(
        Sb3System(model, args.elevation), "verti-100", tasks=args.eval_tasks, out=args.results,
        force=args.results is not None,
    )
    outcomes = Counter(r["outcome"] for r in results)
    print("verti-100 outcomes:", dict(outcomes), f"success rate {outcomes['success'] / len(results):.2f}")
    train.close()


if __name__ == "__main__":
    np.set_printoptions(precision=3)
    main()
