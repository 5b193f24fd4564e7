#!/usr/bin/env python3
"""The rigid-ground table of docs/src/results/chrono.md: verti against Chrono's reference runs
(`../shared/chrono-reference`, 31 tasks) for both HMMWV tyre variants, both starts and both
drivers, each task run 20 times from starts up to 2 cm apart (`verti sim compare --ensemble 20`).

    python3 scripts/chrono_rigid_table.py [VERTI]      # VERTI defaults to target/release/verti

About a minute and a half on two cores. The columns: the first run's outcome agreement and
counts; the ensemble's expected agreement (mean share of runs ending as Chrono's did) and
self-agreement (the chance two of verti's runs of a task end alike), overall and on high
elevation; the expected counts; and, from the first run, the median verti / Chrono time to goal
on common successes and the medians of the per-task ratios of mean |roll| and |pitch|.
"""

import json
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
REFERENCE = ROOT.parent / "shared" / "chrono-reference"
VARIANTS = [
    (vehicle, start, driver)
    for vehicle in ("hmmwv", "hmmwv-handling")
    for start in ("settled", "drop")
    for driver in ("pid", "reference")
]


def compare(verti, vehicle, start, driver, out):
    args = [verti, "sim", "compare", str(REFERENCE), "--vehicle", vehicle, "--start", start]
    args += ["--driver", driver, "--ensemble", "20", "--json", "--out", str(out)]
    if driver == "reference":
        args += ["--inner-dt", "0.005"]
    done = subprocess.run(args, cwd=ROOT, check=True, capture_output=True, text=True)
    return json.loads(done.stdout)


def counts(c):
    return f"{c['success']} / {c['stuck']} / {c['rollover']}" + (f" (+{c['timeout']} timeout)" if c["timeout"] else "")


def expected(c):
    return f"{c['success']:.1f} / {c['stuck']:.1f} / {c['rollover']:.1f}"


def main():
    verti = sys.argv[1] if len(sys.argv) > 1 else str(ROOT / "target/release/verti")
    if not REFERENCE.is_dir():
        sys.exit(f"{REFERENCE}: the reference runs are not here")
    outcomes = REFERENCE / "outcomes.jsonl"
    chrono = [json.loads(line)["outcome"] for line in outcomes.open() if line.strip()]
    print(
        f"31 shared tasks; 20 runs per task, starts up to 2 cm apart. Chrono: "
        f"{chrono.count('success')} success / {chrono.count('stuck')} stuck / {chrono.count('rollover')} rollover."
    )
    print()
    print(
        "| vehicle, start, driver | one run: agreement | one run: success / stuck / rollover | expected agreement "
        "| self-agreement | high elevation: expected / self | expected success / stuck / rollover "
        "| time to goal ratio | mean \\|roll\\| ratio | mean \\|pitch\\| ratio |"
    )
    print("|---|---:|---|---:|---:|---:|---|---:|---:|---:|")
    with tempfile.TemporaryDirectory() as tmp:
        for vehicle, start, driver in VARIANTS:
            d = compare(verti, vehicle, start, driver, Path(tmp) / f"{vehicle}-{start}-{driver}")
            one = next(g for g in d["groups"] if g["group"] == "all")
            ens = {g["group"]: g for g in d["ensemble"]["groups"]}
            name = f"{vehicle}, {start}, {driver}"
            if (vehicle, start, driver) == ("hmmwv", "drop", "reference"):
                name = f"**{name}** (the reference's own set-up)"
            print(
                f"| {name} | {100 * one['agreement']:.0f} % | {counts(one['verti'])} "
                f"| {100 * ens['all']['expected_agreement']:.0f} % | {100 * ens['all']['self_agreement']:.0f} % "
                f"| {100 * ens['high']['expected_agreement']:.0f} % / {100 * ens['high']['self_agreement']:.0f} % "
                f"| {expected(ens['all']['expected'])} | {one['median_time_ratio']:.3f} "
                f"| {one['mean_abs_roll']['median_ratio']:.2f} | {one['mean_abs_pitch']['median_ratio']:.2f} |"
            )


if __name__ == "__main__":
    main()
