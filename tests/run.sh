#!/usr/bin/env bash
# The test command of the README: installs, builds and runs every test.
# Extra arguments go to ctest, e.g. `tests/run.sh -L unit` for the fast part.
set -euo pipefail
cd "$(dirname "$0")/.."
bash deploy/build.sh
ctest --test-dir build --output-on-failure --parallel "$(nproc)" "$@"
