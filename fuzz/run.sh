#!/usr/bin/env bash
# Runs every fuzz target for a bounded time each (default 60 s), one after
# the other, on one core. Needs cargo-fuzz (`cargo install cargo-fuzz`);
# only a stable toolchain is needed: RUSTC_BOOTSTRAP lets cargo-fuzz use
# the nightly-only sanitizer flags.
#
#   fuzz/run.sh [SECONDS] [TARGET...]
#
# A crash leaves its input in fuzz/artifacts/<target>/; reproduce it with
# `RUSTC_BOOTSTRAP=1 cargo fuzz run <target> <file>`, then add it as a
# regression test to the normal test suite.
set -euo pipefail
cd "$(dirname "$0")"
secs="${1:-60}"
shift || true
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  targets=(gjk_query server_request)
fi
export RUSTC_BOOTSTRAP=1
for t in "${targets[@]}"; do
  echo "== $t for ${secs}s"
  mkdir -p "corpus/$t"
  cargo fuzz run "$t" "corpus/$t" -- -max_total_time="$secs" -rss_limit_mb=2048 -print_final_stats=1
done
