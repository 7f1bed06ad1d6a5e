#!/usr/bin/env bash
# The test command of the README: installs, builds and runs every test, then
# the fuzzing targets for a bounded time.
# Extra arguments go to ctest, e.g. `tests/run.sh -L unit` for the fast part.
set -euo pipefail
cd "$(dirname "$0")/.."
# The build directory takes a few GB; a full disk shows as a failed link.
df -h . | awk 'NR == 2 { print "disk free where the build goes: " $4 }'
bash deploy/build.sh
ctest --test-dir build --output-on-failure --parallel "$(nproc)" "$@"
# The whole suite also runs the fuzzing targets, 20 s each, in their own
# clang build (tests/fuzz/README.md); a ctest selection does not.
if [[ $# -eq 0 ]]; then
  bash tests/fuzz/run.sh --seconds 20
fi
