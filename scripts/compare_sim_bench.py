#!/usr/bin/env python3
"""Speed of every built-in vehicle under two verti binaries, run alternately.

    python3 scripts/compare_sim_bench.py OLD_BINARY NEW_BINARY [--rounds 3] [--runs 5]

Each round runs `verti sim bench --runs R --threads 1 --json` with the old binary, then with the
new one, so that both see the same load on a shared machine. The table gives, per vehicle and
ground, the median over the rounds of each binary's median µs per internal step, their ratio,
the new binary's real-time factor, and the distance each drove (a vehicle whose physics changed
drives elsewhere, so the two do not do the same work)."""

import argparse
import json
import statistics
import subprocess
import sys


def bench(binary, runs):
    out = subprocess.run(
        [binary, "sim", "bench", "--runs", str(runs), "--threads", "1", "--json"],
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    return {(c["vehicle"], c["terrain"]): c for c in json.loads(out)["cases"]}


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("old")
    p.add_argument("new")
    p.add_argument("--rounds", type=int, default=3)
    p.add_argument("--runs", type=int, default=5)
    a = p.parse_args()
    rounds = {"old": [], "new": []}
    for r in range(a.rounds):
        for side in ("old", "new"):
            binary = a.old if side == "old" else a.new
            print(f"round {r + 1}/{a.rounds}: {side}", file=sys.stderr)
            rounds[side].append(bench(binary, a.runs))
    print("| vehicle | ground | µs per step before / after | after / before | RTF after (median) | distance before / after (m) |")
    print("|---|---|---|---:|---:|---|")
    for key in rounds["new"][0]:
        old = statistics.median(b[key]["us_per_step"] for b in rounds["old"] if key in b)
        new = statistics.median(b[key]["us_per_step"] for b in rounds["new"])
        rtf = statistics.median(b[key]["real_time_factor"] for b in rounds["new"])
        d_old = rounds["old"][0].get(key, {}).get("distance", float("nan"))
        d_new = rounds["new"][0][key]["distance"]
        print(
            f"| {key[0]} | {key[1]} | {old:.2f} / {new:.2f} | {new / old:.2f} | {rtf:.0f}x "
            f"| {d_old:.1f} / {d_new:.1f} |"
        )


if __name__ == "__main__":
    main()
