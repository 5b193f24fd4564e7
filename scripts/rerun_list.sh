#!/usr/bin/env bash
# Re-runs, in order, the run folders of a change list in benchmarks/in-progress/ (one folder per
# line, `#` comments) after a change of the vehicle itself: each one afresh
# (scripts/rerun_terrain.py --all, resumable), then drops it from the list, packs the runs and
# regenerates the results pages and figures, so that each step can be committed on its own.
#
#   bash scripts/rerun_list.sh [--commit] [--max N] BIN LIST
#
#   BIN       the verti binary (copy target/release/verti elsewhere first if you will rebuild)
#   LIST      e.g. benchmarks/in-progress/before-roll-centres.txt
#   --commit  commit each finished run with its pages (only the paths this script wrote)
#   --max N   stop after N runs (default: the whole list)
#   --every M regenerate the pages (and commit) only once M minutes have passed since the last
#             time, and after the last run (default 0: after every run); a run of a few seconds
#             then does not cost a minute of regeneration
#
# PIETRA's navigation runs (benchmarks/pietra-nav/*) are one `verti pietra navigate` of all
# methods and risk levels: the first of them in the list re-runs all of them, with the table
# and Fig. 7, and drops them all. Stop it at any time: the run under way resumes on the next
# call (`bash scripts/benchmarks.sh checkpoint` commits it as it stands). VertiAdaptor's MAML*
# run (benchmarks/va-nav/maml) first writes its per-world cards again, which needs a BIN built
# with the `learn` feature (cargo build --release -p verti-cli --features learn).
set -euo pipefail
cd "$(dirname "$0")/.."
commit=0
max=1000000
every=0
while [ $# -gt 2 ]; do
    case "$1" in
    --commit) commit=1; shift ;;
    --max) max="$2"; shift 2 ;;
    --every) every="$2"; shift 2 ;;
    *) echo "unknown option $1" >&2; exit 2 ;;
    esac
done
[ $# -eq 2 ] || { sed -n 7,12p "$0" >&2; exit 2; }
bin="$1"
list="$2"
[ -x "$bin" ] || { echo "$bin: not an executable" >&2; exit 2; }
[ -f "$list" ] || { echo "$list: no such list" >&2; exit 2; }

done_runs=0
pending=()          # runs finished since the pages were last regenerated
last_regen=$(date +%s)
regenerate() {
    [ "${#pending[@]}" -gt 0 ] || return 0
    bash scripts/benchmarks.sh pack >/dev/null
    python3 scripts/gen_results.py "$bin" >/dev/null
    bash scripts/figures.sh >/dev/null
    if [ "$commit" = 1 ]; then
        local what="${pending[*]}"
        [ "${#pending[@]}" -le 3 ] || what="${#pending[@]} runs: ${pending[*]}"
        git add -A "${paths[@]}" "$list" docs/src/results docs/src/images benchmarks/in-progress
        git commit -q -m "Re-run after $(basename "$list" .txt): $what; pages and figures regenerated"
    fi
    pending=()
    paths=()
    last_regen=$(date +%s)
}
paths=()
while [ "$done_runs" -lt "$max" ]; do
    run=$(grep -v '^#' "$list" | grep -v '^[[:space:]]*$' | head -n 1 || true)
    [ -n "$run" ] || { echo "$list: nothing left"; break; }
    echo "== $(date +%T) $run"
    start=$(date +%s)
    case "$run" in
    benchmarks/pietra-nav/*)
        work=benchmarks/in-progress/pietra-nav
        "$bin" pietra navigate --out "$work" --resume
        for r in "$work"/*/; do
            r=${r%/}
            rm -rf "benchmarks/pietra-nav/$(basename "$r")"
            mv "$r" benchmarks/pietra-nav/
        done
        mv "$work/table.md" "$work/fig7.png" benchmarks/pietra-nav/
        rmdir "$work"
        grep -v '^benchmarks/pietra-nav/' "$list" >"$list.new"
        paths+=(benchmarks/pietra-nav)
        ;;
    *)
        if [ "$run" = benchmarks/va-nav/maml ]; then
            # MAML*'s per-world cards come from exploration drives with the vehicle, so they are
            # written again (about 12 min) before the run that reads them (vertiadaptor.md).
            rm -rf benchmarks/va-nav/maml-cards
            "$bin" learn va --adapt-to verti-100 --adapt-worlds 1,2,4,5,7,6,8,10,12,13,3,9,20,21,22 \
                --adapt-out benchmarks/va-nav/maml-cards
        fi
        python3 scripts/rerun_terrain.py --bin "$bin" --all "$run"
        grep -vxF "$run" "$list" >"$list.new"
        paths+=("$run")
        ;;
    esac
    mv "$list.new" "$list"
    minutes=$((($(date +%s) - start) / 60))
    done_runs=$((done_runs + 1))
    echo "   $run re-run in $minutes min"
    pending+=("$run ($minutes min)")
    if [ $(($(date +%s) - last_regen)) -ge $((every * 60)) ]; then
        regenerate
    fi
done
regenerate
