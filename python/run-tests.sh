#!/usr/bin/env bash
# The Python package's tests: makes (or reuses) a virtual environment, installs
# maturin, numpy, pytest and the package itself (built from source by pip),
# then runs pytest. Extra arguments go to pytest.
#
#   python/run-tests.sh                 # venv in python/.venv
#   GJKD_VENV=/tmp/venv python/run-tests.sh -k errors
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
venv="${GJKD_VENV:-$here/.venv}"
python="${PYTHON:-python3}"

if [ ! -x "$venv/bin/python" ]; then
  echo "== creating $venv"
  "$python" -m venv "$venv"
fi
echo "== installing maturin, numpy, pytest, mypy and ./python"
"$venv/bin/python" -m pip install --quiet --upgrade pip
"$venv/bin/python" -m pip install --quiet "maturin>=1.7,<2" "numpy>=1.21" "pytest>=7" "mypy>=1.10"
"$venv/bin/python" -m pip install --quiet "$here"
echo "== pytest"
cd "$here"
# pytest itself, not `python -m pytest`, which would put this directory on
# sys.path and import the source tree instead of the installed package.
exec "$venv/bin/pytest" -q "$@"
