#!/usr/bin/env bash
# Installs the gjkd C library, headers, CMake package and pkg-config file:
#
#   ffi/install.sh PREFIX              # builds with cargo --profile dist
#                                      # first (stripped, into target/dist),
#                                      # with robots and meshes
#   ffi/install.sh --no-robots PREFIX  # the same without them: a lean
#                                      # library (no URDF or mesh crates)
#   ffi/install.sh --from DIR PREFIX   # copies an existing build (DIR holds
#                                      # libgjkd_c.so and libgjkd_c.a)
#
# Whether the library has robots is read from the library itself; without
# them, the CMake package and the pkg-config file define GJKD_NO_ROBOTS, so
# that the header hides their declarations and a program calling them
# fails to compile rather than to link.
#
# The shared library is installed as libgjkd_c.so.VERSION, with links
# from its soname (libgjkd_c.so.0.MINOR, what programs record) and from
# libgjkd_c.so (what the linker looks for).
#
# Then find_package(gjkd) finds it with -DCMAKE_PREFIX_PATH=PREFIX, and
# pkg-config with PKG_CONFIG_PATH=PREFIX/lib/pkgconfig.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
from=""
features=(--features robots)
if [[ "${1:-}" == "--no-robots" ]]; then
  features=()
  shift
fi
if [[ "${1:-}" == "--from" ]]; then
  from="${2:?--from needs a folder}"
  shift 2
fi
prefix="${1:?usage: ffi/install.sh [--no-robots] [--from DIR] PREFIX}"

if [[ -z "$from" ]]; then
  target="$(cd "$here/.." && cargo metadata --format-version 1 --no-deps \
    | sed -n 's/.*"target_directory":"\([^"]*\)".*/\1/p')"
  # Two installs at once (one with robots, one without) build the same
  # target/dist/libgjkd_c.so: each holds this lock from its build to the
  # end of its copy, so that neither installs the other's library. (The
  # dist profile keeps installs apart from `cargo build --release` and
  # `cargo run --example`, which build into target/release and
  # target/debug.)
  mkdir -p "$target"
  if command -v flock >/dev/null; then
    exec 9>"$target/.gjkd-install.lock"
    flock 9
  fi
  (cd "$here/.." && cargo build --profile dist -p gjkd-c --lib "${features[@]}")
  from="$target/dist"
fi
version="$(sed -n 's/^version = "\(.*\)"/\1/p' "$here/../Cargo.toml" | head -n1)"

mkdir -p "$prefix/lib/cmake/gjkd" "$prefix/lib/pkgconfig" "$prefix/include"
prefix="$(cd "$prefix" && pwd)"
install -m 644 "$here/include/gjkd.h" "$here/include/gjkd.hpp" "$prefix/include/"
soname="$(readelf -d "$from/libgjkd_c.so" 2>/dev/null \
  | sed -n 's/.*(SONAME).*\[\(.*\)\]/\1/p')"
soname="${soname:-libgjkd_c.so}"
rm -f "$prefix/lib/libgjkd_c.so" "$prefix/lib/$soname"
install -m 755 "$from/libgjkd_c.so" "$prefix/lib/libgjkd_c.so.$version"
if [[ "$soname" != "libgjkd_c.so.$version" ]]; then
  ln -s "libgjkd_c.so.$version" "$prefix/lib/$soname"
fi
if [[ "$soname" != libgjkd_c.so ]]; then
  ln -s "libgjkd_c.so.$version" "$prefix/lib/libgjkd_c.so"
fi
install -m 644 "$from/libgjkd_c.a" "$prefix/lib/"
# The static library carries the debug info of the Rust standard library
# it bundles, whatever the profile, and the LLVM bitcode rustc embeds in
# every crate's objects for its own link-time optimisation: of no use to a
# C program's build (together more than half the archive).
if command -v strip >/dev/null; then
  strip --strip-debug --remove-section=.llvmbc --remove-section=.llvmcmd \
    "$prefix/lib/libgjkd_c.a"
fi
defines=""
cmake_defines=""
if command -v nm >/dev/null \
  && ! nm -D --defined-only "$from/libgjkd_c.so" | grep -q ' gjkd_register_robot\(@.*\)\?$'; then
  defines=" -DGJKD_NO_ROBOTS"
  cmake_defines="GJKD_NO_ROBOTS"
fi
sed "s|@DEFINES@|$cmake_defines|g" "$here/cmake/gjkdConfig.cmake" \
  > "$prefix/lib/cmake/gjkd/gjkdConfig.cmake"
sed "s|@VERSION@|$version|g" "$here/cmake/gjkdConfigVersion.cmake.in" \
  > "$prefix/lib/cmake/gjkd/gjkdConfigVersion.cmake"
sed -e "s|@VERSION@|$version|g" -e "s|@PREFIX@|$prefix|g" -e "s|@DEFINES@|$defines|g" \
  "$here/cmake/gjkd.pc.in" \
  > "$prefix/lib/pkgconfig/gjkd.pc"
echo "installed gjkd $version into $prefix${defines:+ (without robots)}"
