#!/usr/bin/env bash
# Builds the verti Python package into a virtual environment and runs its tests.
#
#   bash python/run_tests.sh            # venv in python/.venv (created if missing)
#   VERTI_VENV=/path/to/venv PYTHON=python3.12 bash python/run_tests.sh
#   VERTI_PROFILE=dev bash python/run_tests.sh   # unoptimised workspace crates, faster build
#   VERTI_WHEEL=0 bash python/run_tests.sh       # skip the wheel check (on by default with release)
#
# Steps: build the extension into the venv (maturin develop), type-check the package, the
# examples and the stubs (mypy, stubtest), run pytest, then build the release wheel and install
# it into a fresh venv (build_wheel.sh).
#
# Needs cargo (the Rust toolchain of the workspace) and Python >= 3.9 with venv; installs the
# pinned tools of requirements-test.txt from PyPI.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
cd "$here"

python="${PYTHON:-python3}"
venv="${VERTI_VENV:-$here/.venv}"
profile="${VERTI_PROFILE:-release}"
# the wheel is a release build: after a release `maturin develop` it reuses that build
if [ "$profile" = "release" ]; then wheel="${VERTI_WHEEL:-1}"; else wheel="${VERTI_WHEEL:-0}"; fi

if ! command -v "$python" >/dev/null 2>&1; then
    echo "run_tests.sh: $python not found; set PYTHON to a Python >= 3.9" >&2
    exit 1
fi
if [ ! -x "$venv/bin/python" ]; then
    echo "== creating virtual environment $venv"
    "$python" -m venv "$venv"
fi
# shellcheck disable=SC1091
source "$venv/bin/activate"
echo "== installing pinned test tools ($(python --version))"
python -m pip install --quiet --disable-pip-version-check -r requirements-test.txt

echo "== building the extension (maturin develop, profile $profile)"
if [ "$profile" = "release" ]; then
    maturin develop --release --quiet
else
    maturin develop --quiet
fi

echo "== mypy (the package, ../examples and tests/stub_usage.py against verti/_verti.pyi)"
# files and settings: [tool.mypy] in pyproject.toml
python -m mypy
echo "== stubtest (verti/_verti.pyi against the built extension)"
python -m mypy.stubtest verti._verti --allowlist stubtest-allowlist.txt

echo "== pytest"
set +e
python -m pytest -q -p no:cacheprovider tests
code=$?
set -e
if [ "$code" -eq 5 ]; then
    echo "run_tests.sh: pytest collected no tests" >&2
    exit 1
fi
if [ "$code" -ne 0 ]; then
    exit "$code"
fi

if [ "$wheel" = "1" ]; then
    PYTHON="$python" bash "$here/build_wheel.sh"
else
    echo "== wheel check skipped (VERTI_WHEEL=$wheel, profile $profile)"
fi
echo "run_tests.sh: passed in ${SECONDS} s"
