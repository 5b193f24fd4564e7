#!/usr/bin/env python3
"""Digest of an evaluation's results, every field but wall_time.

    scripts/results_digest.py RESULTS.jsonl                # print per-task digests
    scripts/results_digest.py RESULTS.jsonl --check REF    # compare with a stored digest file
    scripts/results_digest.py RESULTS.jsonl --check REF --partial   # only the tasks in RESULTS

A digest file has one line per task, "TASK SHA256-PREFIX", sorted by task, and a final line
"all SHA256" over the whole set. Each task's digest is SHA-256 of its result as canonical JSON
(sorted keys, Python's shortest round-trip float repr) without `wall_time`, the one field that
varies between runs. --check names every task whose result differs, missing or extra.
"""

import hashlib
import json
import sys


def digests(path):
    out = {}
    with open(path, encoding="utf-8") as f:
        for n, line in enumerate(f, 1):
            line = line.strip()
            if not line:
                continue
            try:
                row = json.loads(line)
            except json.JSONDecodeError as e:
                sys.exit(f"{path}:{n}: not JSON: {e}")
            row.pop("wall_time", None)
            canon = json.dumps(row, sort_keys=True, separators=(",", ":"), allow_nan=True)
            task = row.get("task")
            if task in out:
                sys.exit(f"{path}:{n}: task {task} appears twice")
            out[task] = hashlib.sha256(canon.encode()).hexdigest()[:16]
    return out


def render(d):
    lines = [f"{t} {h}" for t, h in sorted(d.items())]
    total = hashlib.sha256("\n".join(lines).encode()).hexdigest()
    return lines + [f"all {total}"]


def main(argv):
    partial = "--partial" in argv
    argv = [a for a in argv if a != "--partial"]
    if len(argv) not in (2, 4) or (len(argv) == 4 and argv[2] != "--check"):
        sys.exit(__doc__)
    lines = render(digests(argv[1]))
    if len(argv) == 2:
        print("\n".join(lines))
        return 0
    with open(argv[3], encoding="utf-8") as f:
        ref = [l.strip() for l in f if l.strip()]
    if ref == lines:
        print(f"{argv[1]}: {len(lines) - 1} results identical to {argv[3]} ({lines[-1]})")
        return 0
    want = dict(l.split(" ", 1) for l in ref if not l.startswith("all "))
    got = dict(l.split(" ", 1) for l in lines if not l.startswith("all "))
    keys = set(got) if partial else set(want) | set(got)
    bad = sorted(keys, key=int)
    bad = [t for t in bad if want.get(t) != got.get(t)]
    if partial and not bad:
        print(f"{argv[1]}: its {len(got)} results are identical to those in {argv[3]}")
        return 0
    for t in bad[:20]:
        print(f"task {t}: expected {want.get(t, 'missing')}, got {got.get(t, 'missing')}")
    print(f"{argv[1]}: {len(bad)} of {len(keys)} results differ from {argv[3]}")
    return 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
