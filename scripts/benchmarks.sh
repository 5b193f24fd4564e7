#!/usr/bin/env bash
# The full evaluations behind the README's tables live in benchmarks/<set>/<system>/ (or deeper,
# e.g. benchmarks/perception-ablation/<model>/<system>/): run.json
# and results.jsonl.gz are committed (gzip keeps ~1 MB of JSON lines per run to ~0.1 MB);
# results.jsonl, the file `verti eval --resume` appends to and `verti report` reads, is not.
#   bash scripts/benchmarks.sh unpack   # results.jsonl from each .gz (an existing newer one is kept)
#   bash scripts/benchmarks.sh pack     # .gz from each results.jsonl (before committing)
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
    echo "usage: bash scripts/benchmarks.sh pack|unpack" >&2
    exit 2
    ;;
esac
