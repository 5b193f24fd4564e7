#!/usr/bin/env bash
# Builds the verti Python package into a virtual environment and runs its tests.
#
#   bash python/run_tests.sh            # venv in python/.venv (created if missing)
#   VERTI_VENV=/path/to/venv PYTHON=python3.12 bash python/run_tests.sh
#   VERTI_PROFILE=dev bash python/run_tests.sh   # unoptimised workspace crates, faster build
#
# Needs cargo (the Rust toolchain of the workspace) and Python >= 3.9 with venv; installs the
# pinned tools of requirements-test.txt from PyPI.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
cd "$here"

python="${PYTHON:-python3}"
venv="${VERTI_VENV:-$here/.venv}"
profile="${VERTI_PROFILE:-release}"

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

echo "== pytest"
set +e
python -m pytest -q -p no:cacheprovider tests
code=$?
set -e
if [ "$code" -eq 5 ]; then
    echo "run_tests.sh: pytest collected no tests" >&2
    exit 1
fi
exit "$code"
