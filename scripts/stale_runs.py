#!/usr/bin/env python3
"""Which committed runs a results page quotes were made before the engine's latest soil change
(SCM's bulldozing) on their deformable and mixed tasks, as one paragraph for the page.

    python3 scripts/stale_runs.py docs/src/results/verti-bench.md

The runs still to be re-run are listed, one folder per line, in
benchmarks/in-progress/before-bulldozing.txt (`scripts/rerun_terrain.py` re-runs them; a folder
leaves the list when its deformable and mixed tasks have been re-run). A page's runs are the
runs its `verti report` blocks and `scripts/table_one.py` blocks show and every run folder its
text names.
"""

import re
import sys
from pathlib import Path

import method_tables

ROOT = Path(__file__).resolve().parent.parent
LIST = ROOT / "benchmarks/in-progress/before-bulldozing.txt"
TABLE_ONE = ["pid", "eh", "mppi", "rl", "mcl", "acl", "wmvct", "mppi6", "tal", "tnt"]
# what the table scripts read (folder prefixes), where the runs are not named on the page
SCRIPT_PREFIXES = {
    "robustness_table.py": ["benchmarks/perception-"],
    "pietra_validation_table.py": ["benchmarks/pietra-validation/"],
    "pietra_nav_table.py": ["benchmarks/pietra-nav/"],
    "va_table4.py": ["benchmarks/va-nav/", "benchmarks/verti-100/va"],
    "vehicles_table.py": ["benchmarks/vehicles/"],
}


def stale():
    if not LIST.exists():
        return set()
    return {line.strip().rstrip("/") for line in LIST.read_text().splitlines() if line.strip() and not line.startswith("#")}


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
    old = stale()
    prefixes = [p for script, ps in SCRIPT_PREFIXES.items() if f"scripts/{script}" in text for p in ps]
    hits = sorted(r for r in old if r in page_runs(text) or any(r.startswith(p) for p in prefixes))
    if not hits:
        print("Every run this page quotes includes the latest soil model (SCM's bulldozing).")
        return
    if len(hits) <= 8:
        names = ", ".join(f"`{h.removeprefix('benchmarks/')}`" for h in hits)
    else:
        groups = {}
        for h in hits:
            groups.setdefault(h.removeprefix("benchmarks/").split("/")[0], []).append(h)
        names = ", ".join(f"`{g}/` ({len(v)})" for g, v in sorted(groups.items()))
    print(
        f"**Stale on soil:** the deformable and mixed tasks of {len(hits)} run(s) quoted here "
        f"were made before SCM's bulldozing joined the soil model and are being re-run "
        f"(`benchmarks/in-progress/README.md`): {names}. Their rigid tasks are current. The "
        f"generated tables show every other run as re-run; the prose between them was written "
        f"before bulldozing and is revised once these runs are done: where it quotes a figure "
        f"the tables no longer show, the tables are right."
    )


if __name__ == "__main__":
    main()
