#!/usr/bin/env python3
"""PIETRA's navigation benchmark (Fig. 7) as a table, from the committed runs.

    bash scripts/benchmarks.sh unpack && python3 scripts/pietra_nav_table.py [benchmarks/pietra-nav]

`verti pietra navigate` writes one run per method and risk level α (`METHOD-aALPHA/`) over the
100 tasks of the PIETRA test maps. The table gives each method's success rate at each α and
its mean time to goal over the successful trials, bold for the best success of each column.
The documentation's PIETRA page embeds it (scripts/gen_results.py)."""

import pathlib
import sys

from run_rows import rows

ROOT = pathlib.Path(__file__).resolve().parent.parent
METHODS = [
    ("pietra", "PIETRA"),
    ("pietra-ood", "PIETRA + OOD avoidance"),
    ("evora", "EVORA (+ OOD avoidance)"),
    ("pi", "PI"),
    ("vanilla", "Vanilla"),
    ("physics", "Physics prior"),
]
ALPHAS = ["0.4", "0.6", "0.8"]


def main():
    root = pathlib.Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "benchmarks/pietra-nav"
    cells = {}
    for method, _ in METHODS:
        for alpha in ALPHAS:
            rs = rows(root / f"{method}-a{alpha}")
            if not rs:
                sys.exit(f"pietra_nav_table: no results in {root / f'{method}-a{alpha}'}")
            wins = [r for r in rs if r["outcome"] == "success"]
            time = sum(r["traversal_time"] for r in wins) / len(wins) if wins else float("nan")
            cells[method, alpha] = (100.0 * len(wins) / len(rs), time, len(rs))
    best = {a: max(cells[m, a][0] for m, _ in METHODS) for a in ALPHAS}
    print("| Method | success α 0.4 | α 0.6 | α 0.8 | time to goal α 0.4 / 0.6 / 0.8 (s) |")
    print("|---|---|---|---|---|")
    for method, name in METHODS:
        shares = []
        for a in ALPHAS:
            s = f"{cells[method, a][0]:.0f} %"
            shares.append(f"**{s}**" if cells[method, a][0] == best[a] else s)
        times = " / ".join(f"{cells[method, a][1]:.1f}" for a in ALPHAS)
        print(f"| {name} | " + " | ".join(shares) + f" | {times} |")


if __name__ == "__main__":
    main()
