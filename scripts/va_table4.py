#!/usr/bin/env python3
"""VertiAdaptor's Table IV on 150 tasks (docs/src/results/vertiadaptor.md) from the committed
runs: the 10 tasks of the first five verti-100 worlds of each elevation level, as the page
lists them, cut out of benchmarks/verti-100/{va,va-every,va-rls,pid,tal} (1000 tasks each) and
benchmarks/va-nav/maml (MAML*'s run of these 150), and summarised by `verti report` (the same statistics as any report: success, and the mean and
population variance across trials of the traversal time and of each trial's mean |roll| and
|pitch|).

    python3 scripts/va_table4.py [VERTI]     # VERTI defaults to target/release/verti
    python3 scripts/va_table4.py [VERTI] --fig docs/src/images/va-table4-fig6.png
                                             # also the report's Fig. 6 of the three variants

Table 1: per level and variant. Table 2: all 150 tasks, the three variants beside PID and TAL
on the same tasks.
"""

import json
import pathlib
import shutil
import subprocess
import sys
import tempfile

from run_rows import rows

ROOT = pathlib.Path(__file__).resolve().parent.parent
TASKS = {
    "low": "1-20,31-50,61-70",
    "mid": "51-60,71-80,91-100,111-130",
    "high": "21-30,81-90,191-220",
}
VARIANTS = [
    ("va", "VA* (once)"),
    ("va-every", "VA† (every 5 s)"),
    ("va-rls", "VA-RLS"),
    ("maml", "MAML* (once)"),
]
# where each run is: the 1000-task runs of verti-100, and MAML*'s own 150-task run
SOURCES = {"maml": "benchmarks/va-nav/maml"}
BESIDE = [("pid", "PID (same tasks)"), ("tal", "TAL (same tasks)")]


def task_set():
    out = set()
    for spec in TASKS.values():
        for part in spec.split(","):
            a, _, b = part.partition("-")
            out |= set(range(int(a), int(b or a) + 1))
    return out


def summaries(verti, runs, tmp, fig=None):
    """`verti report --json` over the 150-task cut of each committed run; with `fig`, also the
    report's Fig. 6 of the VertiAdaptor variants, written there."""
    tasks = task_set()
    dirs = []
    for name in runs:
        src = ROOT / SOURCES.get(name, f"benchmarks/verti-100/{name}")
        dst = tmp / name
        dst.mkdir()
        shutil.copy(src / "run.json", dst / "run.json")
        with open(dst / "results.jsonl", "w") as out:
            for r in rows(src, tasks):
                out.write(json.dumps(r) + "\n")
        dirs.append(str(dst))
    text = subprocess.run(
        [verti, "report", "--json", *dirs], check=True, capture_output=True, text=True
    ).stdout
    if fig:
        out = tmp / "report"
        variants = dirs[: len(VARIANTS)]  # the VertiAdaptor variants and MAML*
        subprocess.run(
            [verti, "report", "--out", str(out), *variants], check=True, capture_output=True
        )
        shutil.copy(out / "fig6.png", fig)
    return json.loads(text)["systems"]


def cell(stat):
    return f"{stat['mean']:.2f} ± {stat['var']:.2f}"


def main():
    args = sys.argv[1:]
    fig = None
    if "--fig" in args:
        k = args.index("--fig")
        fig = args[k + 1]
        del args[k : k + 2]
    verti = args[0] if args else str(ROOT / "target" / "release" / "verti")
    names = [n for n, _ in VARIANTS + BESIDE]
    labels = dict(VARIANTS + BESIDE)
    with tempfile.TemporaryDirectory() as tmp:
        systems = summaries(verti, names, pathlib.Path(tmp), fig)
    if len(systems) != len(names):
        sys.exit(f"va_table4: expected {len(names)} systems in the report, got {len(systems)}")
    by_name = dict(zip(names, systems))
    print("| level | method | success | traversal time (s) | roll (°) | pitch (°) |")
    print("|---|---|---|---|---|---|")
    for level in TASKS:
        for name, label in VARIANTS:
            row = next(g for g in by_name[name]["by_level"] if g["group"] == level)
            print(
                f"| {level} | {label} | {row['successes']}/{row['trials']} | "
                f"{cell(row['traversal_time'])} | {cell(row['roll'])} | {cell(row['pitch'])} |"
            )
    print()
    print("| all 150 tasks | " + " | ".join(labels[n] for n in names) + " |")
    print("|---" * (len(names) + 1) + "|")
    print(
        "| success | "
        + " | ".join(f"{by_name[n]['outcomes']['success_pct']:.1f} %" for n in names)
        + " |"
    )
    print(
        "| rollover / stuck / timeout | "
        + " | ".join(
            "{rollover_pct:.1f} / {stuck_pct:.1f} / {timeout_pct:.1f}".format(
                **by_name[n]["outcomes"]
            )
            for n in names
        )
        + " |"
    )


if __name__ == "__main__":
    main()
