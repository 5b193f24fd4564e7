"""A random policy on verti/Navigate-v0: one episode, a summary, and a PNG of the top view.

    python examples/random_rollout.py [--task 1] [--seed 0] [--png rollout.png]

Needs only the verti package (see python/README.md); the PNG is written with the standard
library's zlib, so no imaging package is required.
"""

import argparse
import struct
import zlib

import gymnasium as gym
import numpy as np

import verti  # noqa: F401  (registers verti/Navigate-v0)


def write_png(path, rgb):
    """Minimal PNG writer for an H x W x 3 uint8 array."""
    h, w, _ = rgb.shape
    raw = b"".join(b"\x00" + rgb[r].tobytes() for r in range(h))

    def chunk(tag, data):
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF)

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)) + chunk(b"IDAT", zlib.compress(raw, 6)) + chunk(b"IEND", b""))


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--world", default="verti-100:1", help="world name (default verti-100:1)")
    p.add_argument("--task", type=int, default=1, help="global task number (world 1 has tasks 1..10)")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--png", default="rollout.png")
    args = p.parse_args()

    env = gym.make("verti/Navigate-v0", world=args.world, task=args.task, render_mode="rgb_array")
    obs, info = env.reset(seed=args.seed)
    env.action_space.seed(args.seed)
    print(f"task {info['task']} on {info['world_name']} ({info['level']}, {info['terrain_type']}, {info['density']}): "
          f"{info['distance_to_goal']:.1f} m to the goal")
    total, steps = 0.0, 0
    while True:
        action = env.action_space.sample()
        action[0] = 0.5 + 0.5 * action[0]  # mostly forward, so the random walk goes somewhere
        obs, reward, terminated, truncated, info = env.step(action)
        total += float(reward)  # gymnasium types the reward as SupportsFloat
        steps += 1
        if terminated or truncated:
            break
    m = info["metrics"]
    print(f"{steps} steps, outcome {info['outcome']} after {m['time']:.1f} s, return {total:.1f}")
    print(f"path {m['path_length']:.1f} m, {m['final_distance']:.1f} m left, mean |roll| {m['roll']['abs']['mean']:.1f} deg, "
          f"mean |pitch| {m['pitch']['abs']['mean']:.1f} deg")
    write_png(args.png, env.render())
    print(f"wrote {args.png}")
    env.close()


if __name__ == "__main__":
    main()
