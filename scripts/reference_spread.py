#!/usr/bin/env python3
"""How verti's outcomes compare with the spread of Chrono's own outcomes, task by task.

    python3 scripts/reference_spread.py soil        # the soil reference set
    python3 scripts/reference_spread.py sections    # the friction-sections set
    python3 scripts/reference_spread.py soil --vehicle my-hmmwv.yaml   # another vehicle file

The reference files in ../shared/chrono-reference hold one Chrono run per task. Many tasks are
chaotic: Chrono itself, re-run from a start a few centimetres away (or on another build), ends
some of them another way. `benchmarks/chrono-members/SET.jsonl` holds such re-runs, made with
the harness of ../shared/chrono-anchor (Chrono 9.0.1 built here, the reference's set-up):
member 0 from the task's own start, members 1-3 from starts up to 2 cm away (`start_offset`).
Every task has at least one re-run; the tasks on which verti and the reference file disagree
have four.

This script runs `verti sim compare` on the set (target/release/verti; reference trials it
leaves out as artifacts stay out) and prints two tables: per ground, Chrono's self-agreement
(the chance that two of its runs of a task end alike, averaged over tasks), verti's agreement
with the reference file, and verti's expected agreement with Chrono's runs (the share of
Chrono's runs of each task that end as verti's does, averaged over tasks); then each task whose
Chrono runs do not all end alike, or on which verti ends otherwise.
"""

import collections
import json
import pathlib
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parent.parent
REFERENCE = ROOT.parent / "shared" / "chrono-reference"
SETS = {"soil": REFERENCE / "soil", "sections": REFERENCE / "sections"}


def compare(reference, vehicle):
    verti = ROOT / "target" / "release" / "verti"
    if not verti.is_file():
        sys.exit("reference_spread: no target/release/verti; run `cargo build --release -p verti-cli`")
    with tempfile.TemporaryDirectory() as out:
        done = subprocess.run(
            [str(verti), "sim", "compare", str(reference), "--json", "--out", out, "--vehicle", vehicle],
            cwd=ROOT,
            check=True,
            capture_output=True,
            text=True,
        )
    return json.loads(done.stdout)


def pairwise_agreement(draws):
    counts = collections.Counter(draws)
    n = len(draws)
    return sum(c * (c - 1) for c in counts.values()) / (n * (n - 1))


def main():
    args = sys.argv[1:]
    vehicle = "hmmwv"
    if len(args) == 3 and args[1] == "--vehicle":
        vehicle = args[2]
        args = args[:1]
    if len(args) != 1 or args[0] not in SETS:
        sys.exit(f"usage: reference_spread.py {'|'.join(SETS)} [--vehicle FILE]")
    name = args[0]
    members_file = ROOT / "benchmarks" / "chrono-members" / f"{name}.jsonl"
    members = collections.defaultdict(list)
    for line in members_file.read_text().splitlines():
        m = json.loads(line)
        members[(m["world_index"], m["pair"])].append(m["outcome"])
    # a vehicle file given from elsewhere still names the same file from the repository root
    if pathlib.Path(vehicle).exists():
        vehicle = str(pathlib.Path(vehicle).resolve())
    summary = compare(SETS[name], vehicle)
    rows = []
    for t in summary["tasks"]:
        key = (t["world_index"], t["pair"])
        if key not in members:
            sys.exit(f"{members_file}: no Chrono re-run of world {key[0]} pair {key[1]}")
        draws = [t["reference"]["outcome"]] + members[key]
        rows.append((t, draws))

    groups = [("all", rows)] + [
        (g, [r for r in rows if r[0]["ground"] == g]) for g in summary["grounds"] if len(summary["grounds"]) > 1
    ]
    print(
        "| ground | tasks | Chrono runs per task | Chrono's self-agreement | settled in Chrono | "
        "verti vs the reference file | verti's expected agreement with Chrono's runs |"
    )
    print("|---|---:|---|---:|---:|---:|---:|")
    for g, rs in groups:
        n = len(rs)
        sizes = [len(d) for _, d in rs]
        self_agree = sum(pairwise_agreement(d) for _, d in rs) / n
        settled = sum(len(set(d)) == 1 for _, d in rs)
        file_agree = sum(t["agree"] for t, _ in rs)
        expected = sum(d.count(t["verti"]["outcome"]) / len(d) for t, d in rs)
        print(
            f"| {g} | {n} | {min(sizes)}–{max(sizes)} | {100 * self_agree:.0f} % | {settled} | "
            f"{file_agree} ({100 * file_agree / n:.0f} %) | {expected:.1f} ({100 * expected / n:.0f} %) |"
        )
    print()
    print("| world | pair | ground | Chrono: reference file, then re-runs | verti |")
    print("|---|---:|---|---|---|")
    for t, d in rows:
        if len(set(d)) > 1 or not t["agree"]:
            print(f"| {t['world']} | {t['pair']} | {t['ground']} | {d[0]}; {', '.join(d[1:])} | {t['verti']['outcome']} |")
    if summary.get("excluded"):
        print()
        print("Left out as artifacts of the reference engine: "
              + "; ".join(f"{x['world']} pair {x['pair']}" for x in summary["excluded"]) + ".")


if __name__ == "__main__":
    main()
