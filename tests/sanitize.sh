#!/usr/bin/env bash
# The tests in a build instrumented with AddressSanitizer (with its leak
# checker) and UndefinedBehaviorSanitizer, into ./build-sanitize: a memory
# error, a leak or undefined behaviour fails the test that runs into it,
# even where the test's own assertions pass. Slower than the plain build
# (about 2x to build, 2-3x to run), so on demand, not in the test command:
#   tests/sanitize.sh                 the unit and integration tests
#   tests/sanitize.sh -L e2e          a ctest selection instead (the e2e tests
#                                     labelled multihost and slurm need root;
#                                     -LE "multihost|slurm" leaves them out)
set -euo pipefail
cd "$(dirname "$0")/.."
build=build-sanitize
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DMBOPT_SANITIZE=ON \
  > "$build.configure.log" 2>&1 || { cat "$build.configure.log"; exit 1; }
rm -f "$build.configure.log"
cmake --build "$build" --parallel "$(nproc)"
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=0:strict_string_checks=1:detect_stack_use_after_return=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
selection=("$@")
[[ $# -eq 0 ]] && selection=(-L "unit|integration")
ctest --test-dir "$build" --output-on-failure --parallel "$(nproc)" "${selection[@]}"
