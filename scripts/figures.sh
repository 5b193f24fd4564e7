#!/usr/bin/env bash
# The Fig. 6 images of the results pages, from the committed runs (after `bash
# scripts/benchmarks.sh unpack`): each is `verti report`'s fig6.png over the runs its page
# tabulates, in the page's order.
#
#   bash scripts/figures.sh [VERTI]      # VERTI defaults to target/release/verti
set -euo pipefail
cd "$(dirname "$0")/.."
verti=${1:-target/release/verti}
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
ten="pid eh mppi rl mcl acl wmvct mppi6 tal tnt"
figure() { # IMAGE SET SYSTEM...
    local image=$1 set=$2
    shift 2
    local runs=()
    for s in "$@"; do runs+=("benchmarks/$set/$s"); done
    "$verti" report "${runs[@]}" --out "$tmp/$image" > /dev/null
    cp "$tmp/$image/fig6.png" "docs/src/images/$image.png"
    echo "docs/src/images/$image.png: $set, $*"
}
figure fig6-verti-100 verti-100 pid eh mppi
figure fig6-vb80 vb80 pid eh mppi
figure fig6-rl-family verti-100 pid rl mcl acl
# shellcheck disable=SC2086
figure fig6-ten-verti-100 verti-100 $ten
# shellcheck disable=SC2086
figure fig6-ten-vb80 vb80 $ten
python3 scripts/va_table4.py "$verti" --fig docs/src/images/va-table4-fig6.png > /dev/null
echo "docs/src/images/va-table4-fig6.png: scripts/va_table4.py"
