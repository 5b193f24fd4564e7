#!/usr/bin/env bash
# Bit-identity check of every training family: tiny `verti learn` runs (seconds each) whose
# output files are hashed and compared with scripts/training_digests.txt.
#
#   bash scripts/check_training.sh            # compare with the committed digests
#   bash scripts/check_training.sh --update   # write them (only after a deliberate change)
#
# Run it before and after a refactor of training code: the digests must not move. Training is
# deterministic for a seed, but burn's CPU matrix products pick their SIMD kernels at run time
# (gemm: AVX-512, AVX2, ...), so the committed digests hold on a CPU like the one that wrote
# them (an AVX-512 x86-64); elsewhere, write digests with --update on the old commit first.
# That is also why CI does not run it.
set -euo pipefail
cd "$(dirname "$0")/.."
REF=scripts/training_digests.txt
UPDATE=${1:-}

cargo build --release --locked -q -p verti-cli --features learn
ROOT=$PWD
V=$ROOT/target/release/verti
# a fixed folder and relative paths: the cards record their training command
T=$PWD/target/check-training
rm -rf "$T" && mkdir -p "$T" && cd "$T"

run() { # name, command...: run quietly, fail loudly
    local name=$1
    shift
    if ! "$@" >"$name.log" 2>&1; then
        cat "$name.log" >&2
        echo "check_training: '$name' failed" >&2
        exit 1
    fi
}

# tiny random-exploration datasets: one to train on, one to validate on
run data1 "$V" data generate random --hours 0.02 --seed 1 --threads 2 --out "d1"
run data2 "$V" data generate random --hours 0.02 --seed 2 --threads 2 --out "d2"

# verti-nn: the SWAE terrain model and the patch encoder
run swae "$V" learn swae --data ../../../shared/verti-bench-data/elev_maps \
    --steps 4 --batch 8 --widths 8,8 --latent 8 --projections 10 --eval-every 2 --out "nn/swae.yaml"
run patch "$V" learn patch --steps 4 --batch 8 --widths 8,8 --latent 8 --projections 10 \
    --eval-every 2 --val-patches 16 --out "nn/patch.yaml"

# verti-kino: the four kinodynamic models
for m in mppi6 wmvct tal tnt; do
    run "kino-$m" "$V" learn kino --model "$m" --data "d1" --val "d2" --steps 6 \
        --batch 16 --hidden 8,8 --eval-every 3 --out "kino/$m.yaml"
done

# verti-va: VertiAdaptor and its baselines
for m in va node mlp maml; do
    run "va-$m" "$V" learn va --method "$m" --data "d1" --val "d2" --steps 6 \
        --bases 4 --hidden 8,8 --eval-every 3 --out "va/$m.yaml"
done

# verti-policy: PPO, two updates of the smallest rollout
run rl "$V" learn rl --updates 2 --envs 2 --steps 16 --epochs 1 --minibatch 16 --threads 2 \
    --val-tasks 2 --eval-every 1 --out "policy/rl.yaml"

# verti-pietra: one PIETRA training
run pietra "$V" learn pietra --method pietra --steps 6 --trials-per-map 1 --seed 0 \
    --model-out "pietra/pietra.yaml" --out "pietra/bench"

# hash every file a training wrote, less what measures wall-clock time: a card's
# `wall_time_s` and rates `*_per_s`, a log's `*_s` columns and the RL checkpoint's progress curve
python3 - >digests.txt <<'PY'
import csv, hashlib, io, pathlib
for path in sorted(p for d in ("nn", "kino", "va", "policy", "pietra")
                   for p in pathlib.Path(d).rglob("*") if p.is_file()):
    if path.name == "state.json":
        continue
    data = path.read_bytes()
    if path.suffix == ".yaml":
        data = b"".join(l for l in data.splitlines(True) if b"wall_time_s" not in l and b"_per_s:" not in l)
    elif path.suffix == ".csv":
        rows = list(csv.reader(io.StringIO(data.decode())))
        keep = [i for i, h in enumerate(rows[0]) if not h.endswith("_s")]
        data = "\n".join(",".join(r[i] for i in keep) for r in rows).encode()
    print(f"{hashlib.sha256(data).hexdigest()}  {path}")
PY

if [ "$UPDATE" = "--update" ]; then
    cp digests.txt "$ROOT/$REF"
    echo "check_training: wrote $(wc -l <"$ROOT/$REF") digests to $REF"
elif diff -u "$ROOT/$REF" digests.txt; then
    echo "check_training: all $(wc -l <"$ROOT/$REF") training outputs are bit for bit as committed"
else
    echo "check_training: training outputs differ from $REF (above)" >&2
    exit 1
fi
