#!/usr/bin/env bash
# Builds the mbopt image (Containerfile) with podman, or docker if podman is
# absent, from a tree where deploy/build.sh has run.
#
#   bash deploy/container/build-image.sh [TAG] [BASE]
#
# TAG defaults to localhost/mbopt:latest. BASE is the Debian 12 image to
# start from (default docker.io/library/debian:bookworm-slim); without
# access to a registry, make one from Debian's packages first with
# deploy/container/make-base-image.sh and pass its name.
set -euo pipefail
cd "$(dirname "$0")/../.."
TAG=${1:-localhost/mbopt:latest}
BASE=${2:-docker.io/library/debian:bookworm-slim}
engine=$(command -v podman || command -v docker || true)
[ -n "$engine" ] || { echo "build-image: needs podman or docker" >&2; exit 1; }
for program in build/server/main/mbopt-server build/worker/main/mbopt-worker build/client/mbopt; do
  [ -x "$program" ] || { echo "build-image: $program is missing: run deploy/build.sh first" >&2; exit 1; }
done
# Only the three programs go into the build context.
context=$(mktemp -d)
trap 'rm -rf "$context"' EXIT
mkdir -p "$context/build/server/main" "$context/build/worker/main" "$context/build/client"
cp build/server/main/mbopt-server "$context/build/server/main/"
cp build/worker/main/mbopt-worker "$context/build/worker/main/"
cp build/client/mbopt "$context/build/client/"
strip --strip-debug "$context"/build/*/main/mbopt-* "$context/build/client/mbopt" 2> /dev/null || true
"$engine" build ${ENGINE_BUILD_ARGS:-} --build-arg "BASE=$BASE" -t "$TAG" -f deploy/container/Containerfile "$context"
echo "build-image: built $TAG"
