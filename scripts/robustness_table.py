"""The README's robustness tables: success (%) per system at each perception preset.

    bash scripts/benchmarks.sh unpack && python3 scripts/robustness_table.py

Reads the committed runs: `benchmarks/verti-100/S` (no noise, all 1000 tasks) and
`benchmarks/perception-P/S` for the systems that run on all tasks, and
`benchmarks/perception-P/S-sub100` (P = none too) for those run on every 10th task. A cell with
fewer results than its table's task count says how many it has (a run still in progress).
Success is `outcome == "success"`; nothing else is read.
"""

import json
import sys
from pathlib import Path

PRESETS = ["none", "low", "medium", "high"]
SUBSET = set(range(1, 1001, 10))
# the paper's order, then ours; anything else after them, alphabetically
ORDER = ["pid", "eh", "mppi", "rl", "mcl", "acl", "wmvct", "mppi6", "tal", "tnt", "pietra", "va"]


def order(name):
    return (ORDER.index(name), "") if name in ORDER else (len(ORDER), name)


def success(path, tasks=None):
    """(success %, results counted) of one run's results.jsonl, or None if it does not exist."""
    file = Path(path) / "results.jsonl"
    if not file.exists():
        return None
    rows = [json.loads(line) for line in file.open() if line.strip()]
    if tasks is not None:
        rows = [r for r in rows if r["task"] in tasks]
    if not rows:
        return None
    return 100.0 * sum(r["outcome"] == "success" for r in rows) / len(rows), len(rows)


def cell(result, expected, digits):
    if result is None:
        return "—"
    rate, n = result
    text = f"{rate:.{digits}f}"
    return text if n == expected else f"{text} ({n} of {expected})"


def main(root):
    root = Path(root)
    full, subset = [], []
    for name in {run.name for run in root.glob("perception-*/*") if run.is_dir()}:
        (subset if name.endswith("-sub100") else full).append(name.removesuffix("-sub100"))
    full.sort(key=order)
    subset.sort(key=order)
    print("| system | " + " | ".join(PRESETS) + " |")
    print("|---|" + "---:|" * len(PRESETS))
    for s in full:
        cells = [
            cell(success(root / ("verti-100" if p == "none" else f"perception-{p}") / s), 1000, 1)
            for p in PRESETS
        ]
        print(f"| `{s}` | " + " | ".join(cells) + " |")
    print()
    print("| system (100 tasks) | " + " | ".join(PRESETS) + " |")
    print("|---|" + "---:|" * len(PRESETS))
    for s in subset:
        cells = [cell(success(root / f"perception-{p}" / f"{s}-sub100"), 100, 0) for p in PRESETS]
        print(f"| `{s}` | " + " | ".join(cells) + " |")
    # the fast systems on the same 100 tasks, for comparison
    for s in full:
        cells = [
            cell(success(root / ("verti-100" if p == "none" else f"perception-{p}") / s, SUBSET), 100, 0)
            for p in PRESETS
        ]
        print(f"| `{s}` | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else Path(__file__).resolve().parent.parent / "benchmarks")
