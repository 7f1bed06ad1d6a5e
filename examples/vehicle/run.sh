#!/usr/bin/env bash
# The README's main command: installs, builds, and optimizes the vehicle
# suspension example end to end — an mbopt server and local workers on
# loopback, driven by the mbopt CLI with its embedded defaults.
set -euo pipefail
cd "$(dirname "$0")/../.."
bash deploy/build.sh --programs
exec ./build/client/mbopt run examples/vehicle/vehicle.study.textproto --workers 2 "$@"
