#!/usr/bin/env bash
# The Python package's tests: makes (or reuses) a virtual environment, installs
# maturin, numpy, pytest, mypy, ruff, OMPL's bindings (pip `ompl`, a
# 5 MB wheel: gjkd.ompl's planning tests) and scipy, pin and coal (the
# gradient tests and their example), checks the Python sources' format and
# lints, builds the package into it, then runs pytest. Extra arguments go to
# pytest.
#
# By default the package is built by `maturin develop` in the dev profile,
# in the workspace's target directory: it reuses what `cargo test` built, so
# the whole test command stays short. GJKD_PY_INSTALL=pip builds it as a
# user does, `pip install ./python` (release, from scratch the first time).
#
# GJKD_PY_STEPS picks the steps, in order (all three by default): `setup`
# (the venv, its packages, ruff), `build` (the package) and `test`
# (pytest). ./test.sh runs `setup` while cargo builds and `test` while the
# Rust tests run.
#
#   python/run-tests.sh                 # venv in python/.venv
#   GJKD_VENV=/tmp/venv python/run-tests.sh -k errors
#   GJKD_PY_INSTALL=pip python/run-tests.sh
#   GJKD_PY_STEPS=test python/run-tests.sh -k errors   # rerun pytest only
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
venv="${GJKD_VENV:-$here/.venv}"
python="${PYTHON:-python3}"
steps=" ${GJKD_PY_STEPS:-setup build test} "

if [[ "$steps" == *" setup "* ]]; then
if [ ! -x "$venv/bin/python" ]; then
  echo "== creating $venv"
  "$python" -m venv "$venv"
fi
echo "== installing maturin, numpy, pytest, mypy, ruff and ompl"
"$venv/bin/python" -m pip install --quiet --upgrade pip
"$venv/bin/python" -m pip install --quiet "maturin>=1.7,<2" "numpy>=1.21" "pytest>=7" "mypy>=1.10" \
  "ruff==0.17.6"
# Pinned: a newer ruff may format differently and fail a tree that was clean.
# OMPL's wheels cover fewer platforms than the rest: without them the
# planning tests skip, saying so.
"$venv/bin/python" -m pip install --quiet "ompl>=2,<3" \
  || echo "ompl could not be installed: gjkd.ompl's planning tests will skip"
# The gradient tests check against pinocchio's frame Jacobians and run the
# trajectory optimisation example (scipy) beside its pinocchio + coal
# baseline: wheels of about 40 MB together. Without them those tests skip,
# saying so.
"$venv/bin/python" -m pip install --quiet scipy pin coal \
  || echo "scipy, pin or coal could not be installed: the gradient tests that need them will skip"
echo "== ruff format --check, ruff check"
"$venv/bin/ruff" format --quiet --check "$here"
"$venv/bin/ruff" check --quiet "$here"
fi
if [[ "$steps" == *" build "* ]]; then
if [ "${GJKD_PY_INSTALL:-develop}" = pip ]; then
  "$venv/bin/python" -m pip install --quiet "$here"
else
  echo "== maturin develop (dev profile, shared target directory)"
  (cd "$here" && VIRTUAL_ENV="$venv" "$venv/bin/maturin" develop --quiet)
fi
fi
[[ "$steps" == *" test "* ]] || exit 0
echo "== pytest"
cd "$here"
# pytest itself, not `python -m pytest`, which would put this directory on
# sys.path and import the source tree instead of the installed package.
exec "$venv/bin/pytest" -q "$@"
