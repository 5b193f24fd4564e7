#!/usr/bin/env python3
"""Which committed runs a results page quotes were made before an engine change that calls for
re-runs, as one paragraph per change for the page.

    python3 scripts/stale_runs.py docs/src/results/verti-bench.md

Each change keeps, in benchmarks/in-progress/, a list of the runs still to be re-run, one folder
per line (`scripts/rerun_terrain.py` re-runs them; a folder leaves the list when its re-run is
committed): before-bulldozing.txt (SCM's bulldozing: deformable and mixed tasks) and
before-roll-centres.txt (the HMMWV's roll centres: every task). A page's runs are the runs its
`verti report` blocks and `scripts/table_one.py` blocks show and every run folder its text
names.
"""

import re
import sys
from pathlib import Path

import method_tables

ROOT = Path(__file__).resolve().parent.parent
IN_PROGRESS = ROOT / "benchmarks/in-progress"
# (list, what the change did, which of a run's tasks it touched)
CHANGES = [
    ("before-bulldozing.txt", "SCM's bulldozing joined the soil model", "deformable and mixed"),
    ("before-roll-centres.txt", "the HMMWV took its linkages' roll centres", "all"),
]
TABLE_ONE = ["pid", "eh", "mppi", "rl", "mcl", "acl", "wmvct", "mppi6", "tal", "tnt"]
# what the table scripts read (folder prefixes), where the runs are not named on the page
SCRIPT_PREFIXES = {
    "robustness_table.py": ["benchmarks/perception-"],
    "pietra_validation_table.py": ["benchmarks/pietra-validation/"],
    "pietra_nav_table.py": ["benchmarks/pietra-nav/"],
    "va_table4.py": ["benchmarks/va-nav/", "benchmarks/verti-100/va"],
    "vehicles_table.py": ["benchmarks/vehicles/"],
}


def stale(list_name):
    path = IN_PROGRESS / list_name
    if not path.exists():
        return set()
    return {line.strip().rstrip("/") for line in path.read_text().splitlines() if line.strip() and not line.startswith("#")}


def all_stale():
    """Every run still to be re-run after any change (Table I's † marks them)."""
    return set().union(*(stale(name) for name, _, _ in CHANGES))


def page_runs(text):
    runs = set()
    for folder, systems in re.findall(r"<!-- report: (\S+) ([^;]+?) ; section:", text):
        runs.update(f"{folder}/{s}" for s in systems.split())
    runs.update(m.rstrip("/.,)`") for m in re.findall(r"benchmarks/[\w./-]+", text))
    for set_name in re.findall(r"scripts/table_one\.py (\S+) ;", text):
        runs.update(f"benchmarks/{set_name}/{s}" for s in TABLE_ONE)
    # the verti-100 tables of the PIETRA and VertiAdaptor pages name their runs in the script
    for number in re.findall(r"scripts/method_tables\.py ; table: (\d+)", text):
        entries = [method_tables.PIETRA, method_tables.VA][int(number) - 1]
        runs.update(f"benchmarks/verti-100/{run}" for _, run in entries)
    return runs


def main():
    page = Path(sys.argv[1])
    text = page.read_text(encoding="utf-8")
    prefixes = [p for script, ps in SCRIPT_PREFIXES.items() if f"scripts/{script}" in text for p in ps]
    quoted = page_runs(text)
    paragraphs = []
    for list_name, change, tasks in CHANGES:
        hits = sorted(r for r in stale(list_name) if r in quoted or any(r.startswith(p) for p in prefixes))
        if hits:
            paragraphs.append(paragraph(hits, change, tasks))
    if not paragraphs:
        print("Every run this page quotes was made with the current engine.")
        return
    print("\n\n".join(paragraphs))


def paragraph(hits, change, tasks):
    if len(hits) <= 8:
        names = ", ".join(f"`{h.removeprefix('benchmarks/')}`" for h in hits)
    else:
        groups = {}
        for h in hits:
            groups.setdefault(h.removeprefix("benchmarks/").split("/")[0], []).append(h)
        names = ", ".join(f"`{g}/` ({len(v)})" for g, v in sorted(groups.items()))
    which = "The tasks" if tasks == "all" else f"The {tasks} tasks"
    current = "" if tasks == "all" else " Their other tasks are current."
    return (
        f"**Stale:** {which} of {len(hits)} run(s) quoted here "
        f"were made before {change} and are being re-run "
        f"(`benchmarks/in-progress/README.md`): {names}.{current} The generated tables show "
        f"every other run as re-run; the prose between them was written before the change and "
        f"is revised once these runs are done: where it quotes a figure the tables no longer "
        f"show, the tables are right."
    )


if __name__ == "__main__":
    main()
