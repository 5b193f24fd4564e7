#!/usr/bin/env python3
"""PIETRA's validation-world tables (docs/src/results/pietra.md, "The risk level α") from the
committed runs in benchmarks/pietra-validation/.

    python3 scripts/pietra_validation_table.py [ROOT]

Table 1: each variant on the 248 validation tasks (`tasks-248.txt`): success, success on mid
and high elevation, rollover, mean speed on high elevation (path length over time, averaged
over the high trials), and the goals it reaches that PIETRA at α 0.5 does not against the
reverse, with the two-sided exact sign test's p. Table 2: the paired comparisons the page
quotes (α 0.8 against PID and MPPI; α 1 against α 0.5 over all 330 high-elevation tasks, the
248 tasks' 165 and the other 165 in `high2-*`).
"""

import pathlib
import sys

from run_rows import paired, rows, share, sign_test, success_by_level

VARIANTS = [
    ("PIETRA, α 0.5 (the default)", "pietra"),
    ("roll/pitch limit off (`max_attitude_deg=90`)", "pietra-att90"),
    ("planning at 20 Hz (`rate=20`), as the MPPI family", "pietra-rate20"),
    ("α 0.8 (`alpha=0.8`)", "pietra-alpha08"),
    ("α 1, risk-neutral (`alpha=1`)", "pietra-alpha1"),
    ("PID", "pid"),
    ("MPPI", "mppi"),
]


def load(root, name):
    """{task: result} of one committed run."""
    return {r["task"]: r for r in rows(root / name)}


def wins(x, y):
    """Tasks x reaches and y does not, and the reverse (tasks both ran)."""
    outcome = lambda run: {t: r["outcome"] for t, r in run.items()}
    return paired(outcome(x), outcome(y))


def main():
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "benchmarks/pietra-validation")
    runs = {name: load(root, name) for _, name in VARIANTS}
    base = runs["pietra"]
    print(
        "| variant, 248 validation tasks | success | mid | high | rollover | "
        "mean speed on high (m/s) | goals gained vs lost against α 0.5 |"
    )
    print("|---|---|---|---|---|---|---|")
    for label, name in VARIANTS:
        results = list(runs[name].values())
        _, mid, high = success_by_level(results)
        on_high = [r for r in results if r["level"] == "high"]
        speed = sum(r["path_length"] / r["time"] for r in on_high if r["time"] > 0) / len(on_high)
        cells = [
            f"{share(results, 'success')} %",
            mid,
            high,
            share(results, "rollover"),
            f"{speed:.2f}",
        ]
        if name == "pietra":
            cells.append("")
        else:
            g, l = wins(runs[name], base)
            cells.append(f"{g} vs {l} (p {sign_test(g, l):.2g})")
        print(f"| {label} | " + " | ".join(cells) + " |")
    print()
    print("| comparison | tasks | goals, first vs second | p |")
    print("|---|---|---|---|")
    pairs = [
        ("α 0.8 against PID", "pietra-alpha08", "pid"),
        ("α 0.8 against MPPI", "pietra-alpha08", "mppi"),
    ]
    for label, a, b in pairs:
        g, l = wins(runs[a], runs[b])
        print(f"| {label} | 248 | {g} vs {l} | {sign_test(g, l):.2g} |")
    # α 1 against α 0.5 on every high-elevation validation task: the 248 tasks' 165 high
    # ones and the other 165
    high = lambda run: {t: r for t, r in run.items() if r["level"] == "high"}
    a1 = high(runs["pietra-alpha1"]) | load(root, "high2-pietra-alpha1")
    a05 = high(base) | load(root, "high2-pietra")
    pid = high(runs["pid"]) | load(root, "high2-pid")
    for label, x, y in [("α 1 against α 0.5, high", a1, a05), ("α 1 against PID, high", a1, pid)]:
        g, l = wins(x, y)
        print(
            f"| {label} ({share(list(x.values()), 'success')} "
            f"against {share(list(y.values()), 'success')} %) | "
            f"{len(x)} | {g} vs {l} | {sign_test(g, l):.2g} |"
        )


if __name__ == "__main__":
    main()
