#!/usr/bin/env python3
"""VertiAdaptor's accuracy tables (Tables II-III, Fig. 3's one-step errors, online adaptation)
from the committed rows of `verti learn va --benchmark` in benchmarks/va-bench/.

    python3 scripts/va_tables.py [DIR]        # DIR defaults to benchmarks/va-bench
    python3 scripts/va_tables.py --transfer [DIR]   # the truck6 transfer (benchmarks/va-truck)

Each rows file (`rows-LABEL.jsonl.gz`, or `.jsonl`) holds, per test world, the error sums of
one model unadapted and adapted ([ErrorSums] in crates/verti-va/src/eval.rs). They are pooled
per model, adaptation and elevation level exactly as `verti learn va --benchmark` pools them for
its table.md: the MSE is the squared error summed over the first 8 rollout steps and the six
pose dimensions, divided by 8 x 6 x rollouts; the one-step error is the summed absolute error
over the number of one-step predictions; adaptation time is the median over the worlds.

Prints, blank-line separated: 1. Tables II-III, 2. one-step mean absolute error on high
(adapted), 3. online adaptation of the shipped VA cards. With --transfer, the
one table of the HMMWV's bases (`va-hmmwv`) against bases trained on the truck6 (`va-truck6`),
both scored on the truck6's test data.
"""

import gzip
import json
import pathlib
import statistics
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
DIMS = ["forward", "left", "up", "yaw", "roll", "pitch"]
LEVELS = ["low", "mid", "high"]
MSE_STEPS = 8
# the paper's models first, then the ablations and the retrained control, then the rest
ORDER = [
    "va",
    "node",
    "maml",
    "mlp",
    "va-small",
    "va-retrained",
    "va-no-semantics",
    "va-no-elevation",
    "va-no-both",
]
NAMES = {
    "va": "VA (`va-v1`)",
    "node": "NODE (`node-v1`)",
    "maml": "MAML (`maml-v1`)",
    "mlp": "MLP (`mlp-v1`)",
    "va-small": "VA small (`va-small-v1`)",
    "va-retrained": "VA, retrained",
    "va-no-semantics": "VA w/o semantics",
    "va-no-elevation": "VA w/o elevation",
    "va-no-both": "VA w/o both",
}
ONLINE = [
    ("", "once (VA*)"),
    ("-every", "every 5 s on the last 5 s (VA†)"),
    ("-rls", "RLS, forgetting 0.98 per step"),
    ("-slide", "a solve every step on the last 5 s"),
]


def read_rows(folder):
    rows = []
    files = sorted(folder.glob("rows-*.jsonl")) + sorted(folder.glob("rows-*.jsonl.gz"))
    seen = set()
    for f in files:
        stem = f.name.removesuffix(".gz")
        if stem in seen:
            continue  # an unpacked copy and its archive: read one
        seen.add(stem)
        opener = gzip.open if f.suffix == ".gz" else open
        with opener(f, "rt") as text:
            for n, line in enumerate(text, 1):
                if line.strip():
                    try:
                        rows.append(json.loads(line))
                    except json.JSONDecodeError as e:
                        sys.exit(f"{f} line {n}: {e}")
    if not rows:
        sys.exit(f"{folder}: no rows-*.jsonl(.gz) files")
    return rows


class Pool:
    """Error sums pooled over worlds, and the adaptation times."""

    def __init__(self):
        self.abs = [0.0] * 6
        self.count = 0
        self.step_sq = None
        self.step_pos = None
        self.step_ang = None
        self.rollouts = 0
        self.times = []

    def add(self, row):
        s = row["sums"]
        self.abs = [a + b for a, b in zip(self.abs, s["one_step_abs"])]
        self.count += s["one_step_count"]
        if self.step_sq is None:
            self.step_sq = [[0.0] * 6 for _ in s["step_sq"]]
        for t, step in enumerate(s["step_sq"]):
            self.step_sq[t] = [a + b for a, b in zip(self.step_sq[t], step)]
        if self.step_pos is None:
            self.step_pos = [0.0] * len(s["step_pos"])
            self.step_ang = [0.0] * len(s["step_ang"])
        # [error, its square] per step: the mean error is the first over the rollouts
        for t, (e, _) in enumerate(s["step_pos"]):
            self.step_pos[t] += e
        for t, (e, _) in enumerate(s["step_ang"]):
            self.step_ang[t] += e
        self.rollouts += s["rollouts"]
        self.times.append(row["adapt_s"])

    def mse(self):
        steps = min(MSE_STEPS, len(self.step_sq))
        total = sum(sum(step) for step in self.step_sq[:steps])
        return total / (steps * 6 * max(self.rollouts, 1))

    def last_step(self):
        """Mean position (m) and angular (rad) error after the last rollout step."""
        n = max(self.rollouts, 1)
        return self.step_pos[-1] / n, self.step_ang[-1] / n

    def mae(self):
        return [a / max(self.count, 1) for a in self.abs]


def pooled(rows):
    pools = {}
    for r in rows:
        pools.setdefault((r["label"], r["adapted"], r["level"]), Pool()).add(r)
    return pools


def seconds(s):
    return f"{s * 1e3:.2f} ms" if s < 0.01 else f"{s:.2f} s"


def transfer(folder):
    pools = pooled(read_rows(folder))
    print("| on truck6, MSE | low | mid | high | mean |")
    print("|---|---|---|---|---|")
    for label, adapted, name in [
        ("va-hmmwv", False, "HMMWV bases, unadapted"),
        ("va-hmmwv", True, "HMMWV bases, one least-squares solve"),
        ("va-truck6", False, "trained on truck6, unadapted"),
        ("va-truck6", True, "trained on truck6, one least-squares solve"),
    ]:
        mses = [pools[(label, adapted, v)].mse() for v in LEVELS if (label, adapted, v) in pools]
        if len(mses) < len(LEVELS):
            sys.exit(f"{folder}: no rows of {label} ({'adapted' if adapted else 'unadapted'}) on every level")
        print(f"| {name} | " + " | ".join(f"{m:.4f}" for m in mses) + f" | {sum(mses) / 3:.4f} |")


def main():
    args = sys.argv[1:]
    if args[:1] == ["--transfer"]:
        transfer(pathlib.Path(args[1]) if len(args) > 1 else ROOT / "benchmarks/va-truck")
        return
    folder = pathlib.Path(args[0]) if args else ROOT / "benchmarks/va-bench"
    rows = read_rows(folder)
    pools = pooled(rows)
    labels = sorted({r["label"] for r in rows}, key=lambda l: (ORDER.index(l) if l in ORDER else len(ORDER), l))
    main_labels = [l for l in labels if l in ORDER]

    def cell(label, adapted, level):
        p = pools.get((label, adapted, level))
        return f"{p.mse():.4f}" if p else "–"

    def worlds(label):
        return sum(1 for r in rows if r["label"] == label and r["adapted"])

    print("| model | adapted low | mid | high | unadapted low | mid | high | adaptation (median) | worlds |")
    print("|---|---|---|---|---|---|---|---|---|")
    for l in main_labels:
        times = [r["adapt_s"] for r in rows if r["label"] == l and r["adapted"]]
        cells = [cell(l, True, v) for v in LEVELS] + [cell(l, False, v) for v in LEVELS]
        print(f"| {NAMES[l]} | {' | '.join(cells)} | {seconds(statistics.median(times))} | {worlds(l)} |")
    print()

    print("| model | " + " | ".join(DIMS) + " | mean |")
    print("|---|" + "---|" * 7)
    for l in main_labels:
        p = pools.get((l, True, "high"))
        if p:
            mae = p.mae()
            print(f"| {NAMES[l]} | " + " | ".join(f"{v:.4f}" for v in mae) + f" | {sum(mae) / 6:.4f} |")
    print()

    # the shipped cards (the benchmark scores every VA card online; the ablations' rows would
    # only repeat the pattern)
    online_cards = [l for l in ["va", "va-small"] if f"{l}-rls" in labels]
    steps = len(next(iter(pools.values())).step_pos)
    print(f"| card | adaptation | low | mid | high | one-step mean, high | after {steps} steps, high: position (m) | angle (rad) |")
    print("|---|---|---|---|---|---|---|---|")
    for card in online_cards:
        for suffix, name in ONLINE:
            l = card + suffix
            p = pools.get((l, True, "high"))
            if p is None:
                continue
            cells = [cell(l, True, v) for v in LEVELS]
            pos, ang = p.last_step()
            print(f"| {NAMES[card]} | {name} | {' | '.join(cells)} | {sum(p.mae()) / 6:.4f} | {pos:.3f} | {ang:.3f} |")


if __name__ == "__main__":
    main()
