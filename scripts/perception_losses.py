"""Why a system loses tasks under perception noise: true cross-track error and where it stops.

Reads two runs of the same system on the same tasks, one without noise and one with a preset,
both made with `--log-steps all`, and prints per preset the true distance from the global path
and, for the trials that end `stuck` under noise, how far the vehicle's centre is from the
nearest obstacle footprint (2.0-2.5 m for a HMMWV is its front against the rock).

    T=$(python3 scripts/perception_losses.py --lost benchmarks/verti-100/pid benchmarks/perception-high/pid)
    verti eval --system pid --tasks $T --log-steps all --out /tmp/losses/none
    verti eval --system pid --tasks $T --log-steps all --perception high --out /tmp/losses/high
    python/.venv/bin/python scripts/perception_losses.py /tmp/losses/none /tmp/losses/high

`--lost A B` prints the tasks solved in run A and not in run B (plain `results.jsonl` files:
`bash scripts/benchmarks.sh unpack` first). The analysis needs the verti package and pandas
(`python/.venv` after `bash python/run_tests.sh`).
"""

import json
import sys
from pathlib import Path

from robustness_table import outcomes  # scripts/ is on the path when this file runs


def results(run):
    with open(Path(run) / "results.jsonl") as f:
        return {r["task"]: r for r in map(json.loads, f) if r}


def lost_tasks(solved_run, noisy_run):
    a, b = outcomes(solved_run), outcomes(noisy_run)
    return sorted(t for t in a.keys() & b.keys() if a[t] == "success" and b[t] != "success")


def distance_to_polyline(points, vertices):
    """Distance of each point (n, 2) to the polyline through `vertices` (m, 2)."""
    import numpy as np

    best = np.full(len(points), np.inf)
    for a, b in zip(vertices[:-1], vertices[1:]):
        ab = b - a
        t = np.clip(((points - a) @ ab) / max(float(ab @ ab), 1e-12), 0.0, 1.0)
        best = np.minimum(best, np.hypot(*(points - (a + t[:, None] * ab)).T))
    return best


def inside(point, polygon):
    x, y = point
    hit = False
    for (x1, y1), (x2, y2) in zip(polygon, list(polygon[1:]) + [polygon[0]]):
        if (y1 > y) != (y2 > y) and x < x1 + (y - y1) * (x2 - x1) / (y2 - y1):
            hit = not hit
    return hit


def obstacle_distance(point, obstacles):
    """Signed distance from `point` to the nearest obstacle edge (negative inside one): rocks are
    footprint polygons, trees circles."""
    import numpy as np

    best = float("inf")
    for o in obstacles:
        fp = np.asarray(o["footprint"])
        if len(fp) == 0:  # a tree: a circle
            best = min(best, float(np.hypot(*(point - o["position"][:2]))) - o["radius"])
            continue
        d = float(distance_to_polyline(point[None, :], np.vstack([fp, fp[:1]]))[0])
        best = min(best, -d if inside(point, fp) else d)
    return best


def analyse(clean_run, noisy_run):
    import numpy as np
    import pandas as pd
    import verti

    worlds = {}
    rows = []
    for label, run in (("clean", clean_run), ("noisy", noisy_run)):
        meta = json.loads((Path(run) / "run.json").read_text())
        if label == "clean":
            worlds = {w.index: w for w in verti.load_worlds(meta["worlds"])}
        for task, r in sorted(results(run).items()):
            steps = pd.read_parquet(Path(run) / "steps" / f"task-{task:05d}.parquet")
            xy = steps[["x", "y"]].to_numpy()
            world = worlds[r["world"]]
            path = np.asarray(world.path(r["pair"]))
            off = distance_to_polyline(xy[::10], path)
            rows.append(
                dict(
                    run=label,
                    task=task,
                    level=r["level"],
                    outcome=r["outcome"],
                    offset_mean=off.mean(),
                    offset_max=off.max(),
                    end_to_obstacle=obstacle_distance(xy[-1], world.obstacles),
                )
            )
    df = pd.DataFrame(rows)
    print("true distance from the global path per trial (m), medians over trials:")
    print(df.groupby("run")[["offset_mean", "offset_max"]].median().round(2).to_string())
    stuck = df[(df.run == "noisy") & (df.outcome == "stuck")]
    near = stuck.end_to_obstacle < 3.0
    print(f"\nstuck with noise: {len(stuck)}; ending with the centre within 3 m of an obstacle: {near.sum()}")
    print(f"  of which 2.0-2.5 m (a HMMWV's front against it): {stuck.end_to_obstacle.between(2.0, 2.5).sum()}")
    print("\nstuck trials by level:")
    print(pd.crosstab(stuck.level, near.map({True: "near an obstacle", False: "elsewhere"})).to_string())


def main(argv):
    if len(argv) == 3 and argv[0] == "--lost":
        print(",".join(map(str, lost_tasks(argv[1], argv[2]))))
    elif len(argv) == 2:
        analyse(argv[0], argv[1])
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main(sys.argv[1:])
