#!/usr/bin/env bash
# The full evaluations behind the README's tables live in benchmarks/<set>/<system>/ (or deeper,
# e.g. benchmarks/perception-ablation/<model>/<system>/): run.json
# and results.jsonl.gz are committed (gzip keeps ~1 MB of JSON lines per run to ~0.1 MB);
# results.jsonl, the file `verti eval --resume` appends to and `verti report` reads, is not.
#   bash scripts/benchmarks.sh unpack   # results.jsonl from each .gz (an existing newer one is kept)
#   bash scripts/benchmarks.sh pack     # .gz from each results.jsonl (before committing)
#   bash scripts/benchmarks.sh checkpoint   # .gz of the runs still being made in benchmarks/in-progress/
# A run being made may be mid-line: `checkpoint` packs its complete lines only, so that a
# committed checkpoint unpacks to a run that `verti eval --resume` continues.
set -euo pipefail
cd "$(dirname "$0")/.."
what=${1:-}
case "$what" in
pack)
    # runs still being made under benchmarks/in-progress/ are not packed: they are not committed
    find benchmarks -path benchmarks/in-progress -prune -o -name results.jsonl -print | sort | while read -r f; do
        # -n: no name or time stamp, so an unchanged file packs to the same bytes
        gzip -9 -n -c "$f" > "$f.gz.tmp" && mv "$f.gz.tmp" "$f.gz"
        echo "packed $f ($(wc -l < "$f") results)"
    done
    ;;
checkpoint)
    find benchmarks/in-progress -name results.jsonl | sort | while read -r f; do
        python3 -c 'import json, sys
for line in open(sys.argv[1]):
    if not line.endswith("\n"):
        break
    json.loads(line)
    sys.stdout.write(line)' "$f" | gzip -9 -n > "$f.gz.tmp" && mv "$f.gz.tmp" "$f.gz"
        echo "checkpoint $f ($(gzip -dc "$f.gz" | wc -l) complete results)"
    done
    ;;
unpack)
    find benchmarks -name results.jsonl.gz | sort | while read -r g; do
        f=${g%.gz}
        if [ -e "$f" ] && [ "$(wc -l < "$f")" -ge "$(gzip -dc "$g" | wc -l)" ]; then
            echo "kept $f (as many results as the archive or more)"
            continue
        fi
        gzip -dc "$g" > "$f.tmp" && mv "$f.tmp" "$f"
        echo "unpacked $f ($(wc -l < "$f") results)"
    done
    ;;
*)
    echo "usage: bash scripts/benchmarks.sh pack|unpack|checkpoint" >&2
    exit 2
    ;;
esac
