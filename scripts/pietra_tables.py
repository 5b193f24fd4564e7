#!/usr/bin/env python3
"""PIETRA's Tables I and II from the committed learning benchmark, beside the paper's.

    python3 scripts/pietra_tables.py [benchmarks/pietra-bench/tables.md]

Reads the tables `verti learn pietra --benchmark` wrote (test EMD² summed over the four
parameters, mean ± std over the seeds of the configuration chosen on validation) and prints
them rounded to two decimals with the paper's Overall / ID / OOD beside each row (PIETRA paper,
Tables I and II), bold for the best mean of each column. The documentation's PIETRA page
embeds both (scripts/gen_results.py)."""

import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent

# The paper's Overall / ID / OOD, by the row names the benchmark writes.
PAPER_I = {
    "PIETRA": "2.77 / 2.68 / 2.78",
    "Physics-Informed (PI)": "2.99 / 2.68 / 3.02",
    "Vanilla": "3.05 / 2.74 / 3.08",
    "EVORA": "3.30 / 2.72 / 3.35",
    "Physics Prior": "3.09 / 2.93 / 3.10",
    "Uniform Prior": "4.35 / 4.34 / 4.35",
}
PAPER_II = {
    "PP & UPI (PIETRA)": "2.77 / 2.68 / 2.78",
    "UPI": "3.27 / 2.67 / 3.32",
    "PP": "2.86 / 2.73 / 2.87",
    "Use phys. model if OOD": "2.93 / 2.72 / 2.95",
    "EVORA": "3.30 / 2.72 / 3.35",
}
# the page's names for the two priors
NAMES = {"Physics Prior": "Physics prior", "Uniform Prior": "Uniform prior"}


def tables(path):
    """{heading: [row cells]} of the `## Table ...` sections."""
    out, heading = {}, None
    for line in path.read_text().splitlines():
        if line.startswith("## "):
            heading = line[3:].strip()
            out[heading] = []
        elif heading and line.startswith("| ") and not line.startswith("| Method"):
            out[heading].append([c.strip() for c in line.strip("|").split("|")])
    return out


def mean(cell):
    return float(cell.split("±")[0])


def rounded(cell):
    parts = [float(p) for p in cell.split("±")]
    return " ± ".join(f"{p:.2f}" for p in parts)


def table(rows, paper, with_choice, first):
    best = [min(mean(r[i]) for r in rows) for i in (1, 2, 3)]
    head = f"| {first} | Overall | ID | OOD |" + (" chosen on validation |" if with_choice else "")
    head += " paper Overall / ID / OOD |\n"
    head += "|---|---|---|---|" + ("---|" if with_choice else "") + "---|\n"
    lines = []
    for r in rows:
        name = r[0]
        cells = []
        for i in (1, 2, 3):
            text = rounded(r[i])
            cells.append(f"**{text}**" if mean(r[i]) == best[i - 1] else text)
        line = f"| {NAMES.get(name, name)} | " + " | ".join(cells) + " |"
        if with_choice:
            line += f" {r[5]} |"
        if name not in paper:
            sys.exit(f"pietra_tables: no paper row for `{name}`")
        lines.append(line + f" {paper[name]} |")
    return head + "\n".join(lines) + "\n"


def main():
    path = pathlib.Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "benchmarks/pietra-bench/tables.md"
    t = tables(path)
    print(table(t["Table I"], PAPER_I, True, "Method"))
    print(table(t["Table II"], PAPER_II, False, "Table II (changes to EVORA)"))


if __name__ == "__main__":
    main()
