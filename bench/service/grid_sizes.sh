#!/usr/bin/env bash
# How the service copes with large results (docs/benchmarks.md, "Service"):
# the vehicle study with its time grid refined to each POINTS value, one job
# each on a fresh server with W workers on 127.0.0.1. Prints per grid: the
# job's outcome and wall time, its analyses, the bytes of one result's
# values as packed (the objective terms and constraint values of one
# analysis, the bulk of a TaskResult: the same bytes on the wire and in the
# log; docs/store.md, "How values are stored"), the job database's size
# after the run and per analysis, and the server's peak resident memory.
#
#   bash bench/service/grid_sizes.sh [W] [POINTS...]
# Defaults: W = 2, POINTS = 101 1001 10001 30001 50001 100001.
set -euo pipefail
cd "$(dirname "$0")/../.."
W=${1:-2}
shift $(( $# >= 1 ? 1 : 0 ))
GRIDS=("$@")
[ ${#GRIDS[@]} -eq 0 ] && GRIDS=(101 1001 10001 30001 50001 100001)
B=build
command -v sqlite3 > /dev/null || { echo "grid_sizes: needs the sqlite3 shell (deploy/install-deps.sh)" >&2; exit 1; }
DIR=$(mktemp -d)
trap 'pkill -P $$ 2>/dev/null || true; rm -rf "$DIR"' EXIT
# shellcheck source=bench/loopback.sh
source bench/loopback.sh

printf '%-8s %-10s %8s %9s %14s %10s %15s %14s\n' points state wall_s analyses result_bytes db_mb db_kb_per_an server_peak_mb
for points in "${GRIDS[@]}"; do
  mkdir -p "$DIR/study"
  sed -E "s/points: [0-9]+/points: $points/" examples/vehicle/vehicle.scene.textproto > "$DIR/study/vehicle.scene.textproto"
  cp examples/vehicle/vehicle.study.textproto "$DIR/study/"
  # shellcheck disable=SC2086  # SERVER_ARGS is a list of words
  start_server ${SERVER_ARGS:-}
  server=$SERVER_PID
  start_workers "$W"
  job=$("$B/client/mbopt" submit "$DIR/study/vehicle.study.textproto" --server "$ADDRESS")
  "$B/client/mbopt" watch "$job" --server "$ADDRESS" > /dev/null || true
  peak_kb=$(awk '/^VmHWM/ {print $2}' "/proc/$server/status")
  stop_service
  db_bytes=$(du -cb "$DIR"/jobs.db* | awk 'END {print $1}')
  sqlite3 -separator ' ' "$DIR/jobs.db" \
    "SELECT j.state, j.wall_seconds, count(a.request_id),
            max(length(a.objective_terms) + length(a.constraint_values))
       FROM jobs j JOIN analyses a ON a.job_id = j.id GROUP BY j.id" |
    awk -v p="$points" -v db="$db_bytes" -v peak="$peak_kb" '{
      printf "%-8s %-10s %8.2f %9d %14d %10.1f %15.1f %14.1f\n", p, $1, $2, $3, $4, db / 1e6, db / 1e3 / $3, peak / 1e3 }'
done
