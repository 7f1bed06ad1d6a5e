#!/usr/bin/env bash
# Runs the image as deploy/README.md describes, on this machine: a server
# container with TLS and tokens, its database on a volume, two worker
# containers and the CLI in a container, all on the host's network but
# listening on 127.0.0.1 only; server and workers on a read-only root file
# system, as deploy/kubernetes runs them. The vehicle study must converge to the same
# result as `mbopt run` on the host, and the server must stop cleanly.
#
#   bash deploy/container/smoke_test.sh [IMAGE]
#
# IMAGE defaults to localhost/mbopt:latest (deploy/container/build-image.sh).
# Not part of the README's test command: it needs podman and an image.
set -euo pipefail
cd "$(dirname "$0")/../.."
IMAGE=${1:-localhost/mbopt:latest}
STUDY=examples/vehicle/vehicle.study.textproto
PORT=$((20000 + $$ % 12000))  # below the ephemeral range (32768 and up)
GUARD_S=60
TEST_NAME="container smoke test"
# shellcheck source=tests/shell/helpers.sh
source tests/shell/helpers.sh
command -v podman > /dev/null || fail "needs podman"
DIR=$(mktemp -d)
name="mbopt-smoke-$$"
cleanup() {
  podman rm -f -t 2 "$name-server" "$name-w1" "$name-w2" > /dev/null 2>&1 || true
  rm -rf "$DIR"
}
trap cleanup EXIT
run() { podman run --network host "$@"; }

# The installation, made by the image itself; the image's user owns it.
uid=$(podman run --rm "$IMAGE" id -u)
run --rm --user 0 -v "$DIR:/out" "$IMAGE" mbopt-server init-tls /out/pki --host 127.0.0.1 --user alice > /dev/null
mkdir -p "$DIR/data"
chown -R "$uid" "$DIR/pki" "$DIR/data"

run -d --read-only --name "$name-server" -v "$DIR/pki:/etc/mbopt/pki:ro" -v "$DIR/data:/var/lib/mbopt" "$IMAGE" \
  mbopt-server --listen "127.0.0.1:$PORT" --tls-dir /etc/mbopt/pki --db /var/lib/mbopt/mbopt.db > /dev/null
server_log() { podman logs "$name-server" 2>&1 || true; }
listening() { [[ "$(server_log)" == *"listening on 127.0.0.1:$PORT"* ]]; }
wait_for "the server container to listen" listening
for w in w1 w2; do
  run -d --read-only --name "$name-$w" -v "$DIR/pki:/pki:ro" -e MBOPT_TLS_CA=/pki/ca.pem -e MBOPT_TOKEN_FILE=/pki/worker.token \
    "$IMAGE" mbopt-worker serve --server "127.0.0.1:$PORT" --name "$w" > /dev/null
done
client() {
  run --rm -v "$DIR/pki:/pki:ro" -v "$PWD/examples:/examples:ro" -e MBOPT_TLS_CA=/pki/ca.pem \
    -e MBOPT_TOKEN_FILE=/pki/alice.token "$IMAGE" mbopt "$@" --server "127.0.0.1:$PORT"
}
job=$(client submit "/$STUDY")
client watch "$job" > /dev/null || fail "$job did not converge"
reference=$(build/client/mbopt run "$STUDY" --json --workers 2 --discard-db | comparable)
expect_same_result "$job" "$(client results "$job" --json | comparable)" "$reference"
podman stop -t 30 "$name-server" > /dev/null
status=$(podman inspect -f '{{.State.ExitCode}}' "$name-server")
[ "$status" = 0 ] || fail "the server exited with $status on SIGTERM"
[ -s "$DIR/data/mbopt.db" ] || fail "no database on the volume"
echo "container smoke test: ok: $IMAGE ran server, 2 workers and the CLI over TLS with tokens; $job converged to mbopt run's result; the server stopped cleanly with its database on the volume"
