#!/usr/bin/env bash
# Checks that the built-in systems still give exactly the recorded results on all 1000 tasks
# of verti-100: every field of every trial but wall_time (digests in tests/behaviour/,
# re-recorded for issue 11, when the default HMMWV took rigid tyres and the belly contact, and
# for issue 34, when soil damping took the wheel surface's speed and the chassis passed through soil,
# and when the edges between rigid patches and soil became curbs and walls: mixed worlds only;
# and for SCM's bulldozing: deformable and mixed worlds; and when the settled start learnt to
# raise a hull the ground would push harder than the weight: tasks 671 and 690; and when the
# HMMWV took its linkages' roll centres: every task).
#
#   bash scripts/check_behaviour.sh            # pid (CI runs this; ~20 s of evaluation)
#   bash scripts/check_behaviour.sh pid eh mppi   # all three (mppi takes ~10 min on 2 cores)
set -euo pipefail
cd "$(dirname "$0")/.."
systems=("$@")
[ ${#systems[@]} -eq 0 ] && systems=(pid)
cargo build --release --locked -q -p verti-cli
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
status=0
for s in "${systems[@]}"; do
    ref="tests/behaviour/$s-verti-100.digest"
    if [ ! -f "$ref" ]; then
        echo "check_behaviour: no recorded digest $ref" >&2
        exit 2
    fi
    start=$(date +%s)
    target/release/verti eval --system "$s" --force --out "$out/$s" > "$out/$s.log" 2>&1 || {
        cat "$out/$s.log" >&2
        exit 1
    }
    echo "== $s: 1000 tasks in $(( $(date +%s) - start )) s"
    python3 scripts/results_digest.py "$out/$s/results.jsonl" --check "$ref" || status=1
done
exit $status
