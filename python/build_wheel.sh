#!/usr/bin/env bash
# Builds the verti wheel, installs it into a fresh temporary virtual environment (no Rust
# toolchain involved: pip only unpacks it) and imports it there.
#
#   bash python/build_wheel.sh                        # maturin must be on PATH
#   VERTI_WHEEL_DIR=dist bash python/build_wheel.sh   # where the wheel goes
#
# The wheel is abi3 (pyo3's abi3-py39 feature): one file, `verti-<version>-cp39-abi3-<platform>.whl`,
# for every CPython >= 3.9 on this platform. It lands in the Cargo workspace's target/wheels unless
# VERTI_WHEEL_DIR says otherwise. run_tests.sh calls this right after `maturin develop --release`,
# whose Rust build `maturin build --release` reuses, so it costs seconds rather than a build.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
cd "$here"

python="${PYTHON:-python3}"
out="${VERTI_WHEEL_DIR:-$here/../target/wheels}"
mkdir -p "$out"
out="$(cd "$out" && pwd)"

scratch="$(mktemp -d "${TMPDIR:-/tmp}/verti-wheel-XXXXXX")"
trap 'rm -rf "$scratch"' EXIT

echo "== building the wheel (maturin build --release)"
# a folder of its own, so the wheel just built is the only one there
maturin build --release --quiet --out "$scratch/dist"
built=("$scratch"/dist/verti-*.whl)
if [ "${#built[@]}" -ne 1 ] || [ ! -f "${built[0]}" ]; then
    echo "build_wheel.sh: expected one wheel from maturin, found: ${built[*]}" >&2
    exit 1
fi
name="$(basename "${built[0]}")"
case "$name" in
    *-cp39-abi3-*) ;;
    *) echo "build_wheel.sh: $name is not an abi3 wheel for CPython >= 3.9" >&2; exit 1 ;;
esac
wheel="$out/$name"
cp "${built[0]}" "$wheel"

echo "== installing it into a fresh virtual environment"
"$python" -m venv "$scratch/venv"
# binaries only: neither verti nor its dependencies may be built from source here
"$scratch/venv/bin/python" -m pip install --quiet --disable-pip-version-check --only-binary=:all: "$wheel"

echo "== smoke check"
# from the scratch folder, so that only the installed package can be imported
(cd "$scratch" && "$scratch/venv/bin/python" - "$scratch/venv" <<'EOF'
import os
import sys
from importlib import metadata

import verti

venv = os.path.realpath(sys.argv[1])
assert os.path.realpath(verti.__file__).startswith(venv + os.sep), f"verti imported from {verti.__file__}"
# the type information travels with the wheel (PEP 561)
files = {str(f) for f in metadata.files("verti") or []}
missing = {"verti/py.typed", "verti/_verti.pyi"} - files
assert not missing, f"the wheel lacks {sorted(missing)}"
world = verti.World.generate(seed=0, index=1, count=3)
names = [s["name"] for s in verti.systems()]
assert "pid" in names and world.tasks, (names, world)
print(f"verti {verti.__version__} on Python {sys.version.split()[0]}: {world!r}; "
      f"{len(names)} systems ({', '.join(names[:4])}, ...); vehicles {', '.join(verti.vehicles())}")
EOF
)
echo "== wheel: $wheel"
