#!/usr/bin/env bash
# Installs the gjkd C library, headers, CMake package and pkg-config file:
#
#   ffi/install.sh PREFIX              # builds with cargo --release first
#   ffi/install.sh --from DIR PREFIX   # copies an existing build (DIR holds
#                                      # libgjkd_c.so and libgjkd_c.a)
#
# Then find_package(gjkd) finds it with -DCMAKE_PREFIX_PATH=PREFIX, and
# pkg-config with PKG_CONFIG_PATH=PREFIX/lib/pkgconfig.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
from=""
if [[ "${1:-}" == "--from" ]]; then
  from="${2:?--from needs a folder}"
  shift 2
fi
prefix="${1:?usage: ffi/install.sh [--from DIR] PREFIX}"

if [[ -z "$from" ]]; then
  (cd "$here/.." && cargo build --release -p gjkd-c --lib)
  target="$(cd "$here/.." && cargo metadata --format-version 1 --no-deps \
    | sed -n 's/.*"target_directory":"\([^"]*\)".*/\1/p')"
  from="$target/release"
fi
version="$(sed -n 's/^version = "\(.*\)"/\1/p' "$here/../Cargo.toml" | head -n1)"

mkdir -p "$prefix/lib/cmake/gjkd" "$prefix/lib/pkgconfig" "$prefix/include"
prefix="$(cd "$prefix" && pwd)"
install -m 644 "$here/include/gjkd.h" "$here/include/gjkd.hpp" "$prefix/include/"
install -m 755 "$from/libgjkd_c.so" "$prefix/lib/"
install -m 644 "$from/libgjkd_c.a" "$prefix/lib/"
install -m 644 "$here/cmake/gjkdConfig.cmake" "$prefix/lib/cmake/gjkd/"
sed "s|@VERSION@|$version|g" "$here/cmake/gjkdConfigVersion.cmake.in" \
  > "$prefix/lib/cmake/gjkd/gjkdConfigVersion.cmake"
sed -e "s|@VERSION@|$version|g" -e "s|@PREFIX@|$prefix|g" "$here/cmake/gjkd.pc.in" \
  > "$prefix/lib/pkgconfig/gjkd.pc"
echo "installed gjkd $version into $prefix"
