#!/usr/bin/env bash
# Installs every Debian 12 package mbopt needs to build, test and run.
# Idempotent; run as root (or with sudo) on a fresh machine. This script is the
# only way dependencies arrive: CI and the README call it.
set -euo pipefail

packages=(
  build-essential cmake pkg-config ninja-build
  libgrpc++-dev protobuf-compiler-grpc libprotobuf-dev protobuf-compiler
  libabsl-dev
  libeigen3-dev
  libsundials-dev
  libsqlite3-dev sqlite3
  libssl-dev
  iproute2
  coinor-libclp-dev
  libgtest-dev libgmock-dev
  libbenchmark-dev
  libnlopt-cxx-dev
  libsimbody-dev
  chromium zlib1g-dev
  clang libclang-rt-14-dev
)

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
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
