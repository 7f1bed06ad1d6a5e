#!/usr/bin/env bash
# Installs the dependencies (deploy/install-deps.sh) and builds mbopt into
# ./build (Ninja; -O2, with line-table debug information unless --programs
# starts the build directory). Safe to run again: it only
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
configure=(-S . -B build -G Ninja)
targets=()
if [ "$mode" = programs ]; then
  bash deploy/install-deps.sh --programs
  # A new build directory for the programs alone is built without debug
  # information, which is about a third of the compiler's time; at -O2 as
  # the test build, so the machine code and the results are the same. A
  # build directory configured before keeps its build type.
  [ -f build/CMakeCache.txt ] || configure+=(-DMBOPT_BUILD_TESTS=OFF -DCMAKE_BUILD_TYPE=Release
    "-DCMAKE_CXX_FLAGS_RELEASE=-O2 -DNDEBUG" "-DCMAKE_C_FLAGS_RELEASE=-O2 -DNDEBUG")
  targets=(--target mbopt mbopt-server mbopt-worker)
else
  bash deploy/install-deps.sh
  # Line tables only (-g1): backtraces keep their files and lines, and the
  # build directory stays a few GB (full -g made it 13 GB and filled a CI
  # machine's disk). The machine code is that of -O2 alone.
  configure+=(-DCMAKE_BUILD_TYPE=RelWithDebInfo -DMBOPT_BUILD_TESTS=ON
    "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O2 -g1 -DNDEBUG" "-DCMAKE_C_FLAGS_RELWITHDEBINFO=-O2 -g1 -DNDEBUG")
fi
cmake "${configure[@]}" > build-configure.log 2>&1 || { cat build-configure.log; exit 1; }
rm -f build-configure.log
cmake --build build --parallel "$(nproc)" "${targets[@]}"
