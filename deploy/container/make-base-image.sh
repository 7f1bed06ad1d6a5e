#!/usr/bin/env bash
# A Debian 12 base image made from Debian's own packages with debootstrap,
# for machines that reach Debian's mirrors but no container registry.
#
#   sudo bash deploy/container/make-base-image.sh [TAG] [MIRROR]
#
# TAG defaults to localhost/debian:bookworm-minbase, MIRROR to
# http://deb.debian.org/debian. Needs root, debootstrap and podman.
set -euo pipefail
TAG=${1:-localhost/debian:bookworm-minbase}
MIRROR=${2:-http://deb.debian.org/debian}
for tool in debootstrap podman; do
  command -v "$tool" > /dev/null || { echo "make-base-image: needs $tool (apt-get install $tool)" >&2; exit 1; }
done
root=$(mktemp -d)
trap 'rm -rf "$root"' EXIT
debootstrap --variant=minbase bookworm "$root" "$MIRROR" > "$root.log" 2>&1 || {
  tail -20 "$root.log" >&2; exit 1; }
rm -f "$root.log"
tar -C "$root" -c . | podman import --change 'CMD ["/bin/bash"]' - "$TAG"
echo "make-base-image: made $TAG"
