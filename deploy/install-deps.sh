#!/usr/bin/env bash
# Installs the Debian 12 packages mbopt needs. Idempotent; run as root (or
# with sudo) on a fresh machine. This script is the only way dependencies
# arrive: CI and the README call it.
#
#   install-deps.sh             everything: build, run, test, benchmark
#   install-deps.sh --programs  only what building and running the three
#                               programs needs (the README's main command)
set -euo pipefail

mode=all
case "${1:-}" in
  "") ;;
  --programs) mode=programs ;;
  *) echo "usage: install-deps.sh [--programs]" >&2; exit 2 ;;
esac

# Building and running mbopt, mbopt-server and mbopt-worker.
packages=(
  build-essential cmake pkg-config ninja-build
  libgrpc++-dev protobuf-compiler-grpc libprotobuf-dev protobuf-compiler
  libabsl-dev
  libeigen3-dev
  libsundials-dev libsuitesparse-dev
  libzip-dev libpugixml-dev zlib1g-dev
  libsqlite3-dev
  libssl-dev
  coinor-libclp-dev
  nlohmann-json3-dev
)
# Tests, benchmarks and the examples that need more: GoogleTest, Google
# Benchmark, NLopt (the peer), Simbody (the multibody oracle), python3 (the
# external-code example's driver; with python3-grpcio and python3-protobuf
# the Python client, client/python, and its tests), Chromium (report screenshots), clang (the
# fuzzers), Slurm and munge (the Slurm test), iproute2 and the sqlite3 shell
# (the multi-host test).
if [ "$mode" = all ]; then
  packages+=(
    sqlite3
    iproute2
    libgtest-dev libgmock-dev
    libbenchmark-dev
    libnlopt-cxx-dev
    libsimbody-dev
    python3 python3-grpcio python3-protobuf
    chromium
    clang libclang-rt-14-dev
    slurmctld slurmd slurm-client munge
  )
fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages already installed"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
# Slurm's packages would start their daemons, which have no configuration
# here: the Slurm test runs a private cluster with its own (tests/slurm).
# So no service is started during this install, and on a machine run by
# systemd the two Slurm daemons are not enabled at boot.
policy=/usr/sbin/policy-rc.d
made_policy=0
if [ ! -e "$policy" ]; then
  printf '#!/bin/sh\n# mbopt install-deps: no service starts during its install\nexit 101\n' | $SUDO tee "$policy" > /dev/null
  $SUDO chmod 755 "$policy"
  made_policy=1
  trap '$SUDO rm -f "$policy"' EXIT
fi
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
if [[ " ${missing[*]} " == *" slurmd "* || " ${missing[*]} " == *" slurmctld "* ]] && [ -d /run/systemd/system ]; then
  $SUDO systemctl disable slurmctld slurmd > /dev/null 2>&1 || true
fi
[ "$made_policy" = 1 ] && $SUDO rm -f "$policy" && trap - EXIT
exit 0
