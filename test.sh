#!/usr/bin/env bash
# Every test of the project, Rust and Python: the README's second command,
# and the last step of CI. The Python tests build the package into a virtual
# environment (python/.venv) from what `cargo test` already built.
set -euo pipefail
cd "$(dirname "$0")"
# The C library's robot and mesh tests need its `robots` feature.
cargo test --workspace --features gjkd-c/robots
bash python/run-tests.sh
