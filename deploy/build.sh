#!/usr/bin/env bash
# Installs the dependencies (deploy/install-deps.sh) and builds mbopt into
# ./build (Release with debug info, Ninja). Safe to run again: it only
# rebuilds what changed.
#
#   build.sh             everything: the programs, the tests, the benchmarks
#   build.sh --programs  mbopt, mbopt-server and mbopt-worker only, with only
#                        their dependencies (the README's main command); a
#                        build directory configured with the tests keeps them
set -euo pipefail
cd "$(dirname "$0")/.."
mode=all
case "${1:-}" in
  "") ;;
  --programs) mode=programs ;;
  *) echo "usage: build.sh [--programs]" >&2; exit 2 ;;
esac
configure=(-S . -B build -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo)
targets=()
if [ "$mode" = programs ]; then
  bash deploy/install-deps.sh --programs
  [ -f build/CMakeCache.txt ] || configure+=(-DMBOPT_BUILD_TESTS=OFF)
  targets=(--target mbopt mbopt-server mbopt-worker)
else
  bash deploy/install-deps.sh
  configure+=(-DMBOPT_BUILD_TESTS=ON)
fi
cmake "${configure[@]}" > build-configure.log 2>&1 || { cat build-configure.log; exit 1; }
rm -f build-configure.log
cmake --build build --parallel "$(nproc)" "${targets[@]}"
