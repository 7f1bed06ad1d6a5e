#!/usr/bin/env bash
# Optimizes a simulator mbopt did not write: quarter_car.py, a python3
# program, declared as the analysis driver "quarter_car" on the local
# workers (quarter_car.drivers.textproto) and named by the study's scene.
# Builds, then starts an mbopt server and two workers on loopback and
# drives them with the mbopt CLI. Needs python3.
set -euo pipefail
cd "$(dirname "$0")/../.."
bash deploy/build.sh
exec ./build/client/mbopt run examples/external/quarter_car.study.textproto --workers 2 \
  --drivers examples/external/quarter_car.drivers.textproto "$@"
