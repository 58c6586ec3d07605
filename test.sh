#!/usr/bin/env bash
# Every test of the project, Rust and Python: the README's second command,
# and the last step of CI. The Python tests build the package into a virtual
# environment (python/.venv) from what `cargo test` already built.
#
# The two suites overlap where they do not compete: the virtual environment
# is made (pip, network-bound) while cargo builds, and pytest runs beside
# the Rust tests, which leave a core idle for long stretches (servers
# starting, C compilers, valgrind, a binary's last long test). Each suite's
# output is printed whole; the script fails if either fails.
set -euo pipefail
cd "$(dirname "$0")"
logs="$(mktemp -d)"
trap 'rm -rf "$logs"' EXIT
py() { GJKD_PY_STEPS="$1" bash python/run-tests.sh; }

py setup >"$logs/setup" 2>&1 &
setup=$!
# The C library's robot and mesh tests need its `robots` feature.
cargo test --workspace --features gjkd-c/robots --no-run
wait "$setup" || { cat "$logs/setup"; exit 1; }
cat "$logs/setup"
# After the Rust build, whose crates `maturin develop` reuses.
py build

py test >"$logs/pytest" 2>&1 &
pytest=$!
rust=0
cargo test --workspace --features gjkd-c/robots || rust=$?
python=0
wait "$pytest" || python=$?
cat "$logs/pytest"
if ((rust != 0 || python != 0)); then
  echo "test.sh: Rust tests exited with $rust, Python tests with $python" >&2
  exit 1
fi
