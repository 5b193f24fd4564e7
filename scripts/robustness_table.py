"""The robustness tables of the documentation (docs/src/results/robustness.md): success (%) per system at each perception preset, and the split of `high` into its map and state errors.

    bash scripts/benchmarks.sh unpack && python3 scripts/robustness_table.py

Reads the committed runs: `benchmarks/verti-100/S` (no noise, all 1000 tasks) and
`benchmarks/perception-P/S` for the systems that run on all tasks, and
`benchmarks/perception-P/S-sub100` for those run on every 10th task at P = low, medium, high
(their noise-free column is their verti-100 run on the same tasks: preset `none` observes what
the plain run does, and its sub-sampled runs matched the plain ones bit for bit). A cell with
fewer results than its table's task count says how many it has (a run still in progress).
Success is `outcome == "success"`; nothing else is read.
"""

import json
import sys
from pathlib import Path

from run_rows import paired

PRESETS = ["none", "low", "medium", "high"]
SUBSET = set(range(1, 1001, 10))
# the paper's order, then ours; anything else after them, alphabetically
ORDER = ["pid", "eh", "mppi", "rl", "mcl", "acl", "wmvct", "mppi6", "tal", "tnt", "pietra", "va"]


def order(name):
    return (ORDER.index(name), "") if name in ORDER else (len(ORDER), name)


def outcomes(path, tasks=None):
    """{task: outcome} of one run's results.jsonl (restricted to `tasks`), or {} if absent."""
    file = Path(path) / "results.jsonl"
    if not file.exists():
        return {}
    rows = (json.loads(line) for line in file.open() if line.strip())
    return {r["task"]: r["outcome"] for r in rows if tasks is None or r["task"] in tasks}


def success(path, tasks=None):
    """(success %, results counted) of one run, or None if it has no results."""
    rows = outcomes(path, tasks)
    if not rows:
        return None
    return 100.0 * sum(o == "success" for o in rows.values()) / len(rows), len(rows)


def lost_gained(clean, noisy, tasks=None):
    """Tasks solved without noise and not with it, and the reverse (on tasks both ran)."""
    a, b = outcomes(clean, tasks), outcomes(noisy, tasks)
    if not a.keys() & b.keys():
        return "—"
    lost, gained = paired(a, b)
    return f"{lost} / {gained}"


def full_run(root, preset, system):
    """A fast system's run at `preset`: without noise it is the plain verti-100 run."""
    return root / ("verti-100" if preset == "none" else f"perception-{preset}") / system


def cell(result, expected, digits):
    if result is None:
        return "—"
    rate, n = result
    text = f"{rate:.{digits}f}"
    return text if n == expected else f"{text} ({n} of {expected})"


def main(root):
    root = Path(root)
    full, subset = [], []
    names = {r.name for p in PRESETS for r in (root / f"perception-{p}").glob("*") if r.is_dir()}
    for name in names:
        (subset if name.endswith("-sub100") else full).append(name.removesuffix("-sub100"))
    full.sort(key=order)
    subset.sort(key=order)
    print("| system | " + " | ".join(PRESETS) + " |")
    print("|---|" + "---:|" * len(PRESETS))
    for s in full:
        cells = [cell(success(full_run(root, p, s)), 1000, 1) for p in PRESETS]
        print(f"| `{s}` | " + " | ".join(cells) + " |")
    print()
    print("| system (100 tasks) | " + " | ".join(PRESETS) + " | lost / gained at high |")
    print("|---|" + "---:|" * (len(PRESETS) + 1))
    for s in subset:
        # without noise a system observes what the plain run does, bit for bit: its verti-100
        # run on the same tasks is the noise-free column
        runs = [
            full_run(root, p, s) if p == "none" else root / f"perception-{p}" / f"{s}-sub100"
            for p in PRESETS
        ]
        cells = [cell(success(run, SUBSET), 100, 0) for run in runs]
        print(f"| `{s}` | " + " | ".join(cells) + f" | {lost_gained(runs[0], runs[-1], SUBSET)} |")
    # the fast systems on the same 100 tasks, for comparison
    for s in full:
        runs = [full_run(root, p, s) for p in PRESETS]
        cells = [cell(success(run, SUBSET), 100, 0) for run in runs]
        print(f"| `{s}` | " + " | ".join(cells) + f" | {lost_gained(runs[0], runs[-1], SUBSET)} |")
    # which part of `high` costs: its map errors alone (`high-without-pose`, an exact state
    # estimate) and its state errors alone (`high-without-map`, the true map)
    ablation = root / "perception-ablation"
    print()
    print("| system | none | `high` | map errors only | state errors only |")
    print("|---|---:|---:|---:|---:|")
    split = [ablation / "high-without-pose", ablation / "high-without-map"]
    for s in full:
        if not all((part / s).is_dir() for part in split):
            continue
        runs = [full_run(root, "none", s), full_run(root, "high", s)] + [part / s for part in split]
        cells = [cell(success(run), 1000, 1) for run in runs]
        print(f"| `{s}` (1000 tasks) | " + " | ".join(cells) + " |")
    for s in sorted({r.name.removesuffix("-sub100") for r in split[0].glob("*-sub100")}, key=order):
        if not all((part / f"{s}-sub100").is_dir() for part in split):
            continue
        high = root / "perception-high" / f"{s}-sub100"
        if not high.is_dir():
            high = full_run(root, "high", s)  # a fast system's 1000-task run, on the same tasks
        runs = [full_run(root, "none", s), high] + [part / f"{s}-sub100" for part in split]
        cells = [cell(success(run, SUBSET), 100, 0) for run in runs]
        print(f"| `{s}` (100 tasks) | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else Path(__file__).resolve().parent.parent / "benchmarks")
