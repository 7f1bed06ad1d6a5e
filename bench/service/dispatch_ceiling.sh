#!/usr/bin/env bash
# How many analyses one server hands out per second when analyses cost
# (almost) nothing (docs/benchmarks.md, "Service"): IN_FLIGHT jobs of STUDY
# at once on one server, WORKERS workers of SLOTS slots each on 127.0.0.1,
# ROUNDS rounds. Prints the analyses per second over the whole run and the
# server's CPU time per analysis. The default study, the landing gear, has
# analyses of about 0.06 ms, so the figure is the service's ceiling, not the
# analyses' (a 2-core machine also runs the workers and the clients).
#
# SERVER_ARGS and WORKER_ARGS (environment) go to mbopt-server and to each
# mbopt-worker. Many slots whose analyses sleep instead of compute (what
# one server can dispatch when the workers are elsewhere):
# WORKER_ARGS="--task-delay-ms 2" with, e.g., 8 workers of 8 slots.
#
# The first figure includes the command-line clients' own start-up (one
# submit, watch and results process per job); the second ("while jobs
# run") is the server's alone: per round, the analyses logged over the time
# from the round's first logged analysis to its last (the analyses'
# committed_unix_ms), summed over the rounds.
#
#   bash bench/service/dispatch_ceiling.sh [IN_FLIGHT] [WORKERS] [SLOTS] [ROUNDS] [STUDY]
set -euo pipefail
cd "$(dirname "$0")/../.."
IN_FLIGHT=${1:-16}
WORKERS=${2:-4}
SLOTS=${3:-8}
ROUNDS=${4:-3}
STUDY=${5:-examples/landing_gear/landing_gear.study.textproto}
B=build
command -v sqlite3 > /dev/null || { echo "dispatch_ceiling: needs the sqlite3 shell (deploy/install-deps.sh)" >&2; exit 1; }
DIR=$(mktemp -d)
trap 'pkill -P $$ 2>/dev/null || true; rm -rf "$DIR"' EXIT

TICKS=$(getconf CLK_TCK)

# shellcheck source=bench/loopback.sh
source bench/loopback.sh
# shellcheck disable=SC2086  # SERVER_ARGS is a list of words
start_server ${SERVER_ARGS:-}
server=$SERVER_PID address=$ADDRESS
# shellcheck disable=SC2086  # WORKER_ARGS is a list of words
start_workers "$WORKERS" --slots "$SLOTS" ${WORKER_ARGS:-}
sleep 0.5
start=$(date +%s.%N)
cpu_start=$(awk '{print $14 + $15}' "/proc/$server/stat")
analyses=0
logged=0 logged_ms=0 rounds=()
for _ in $(seq "$ROUNDS"); do
  jobs=()
  for _ in $(seq "$IN_FLIGHT"); do jobs+=("$("$B/client/mbopt" submit "$STUDY" --server "$address")"); done
  for job in "${jobs[@]}"; do
    "$B/client/mbopt" watch "$job" --server "$address" > /dev/null || true
    # results exits 1 for a job that did not converge: its analyses count all the same.
    n=$({ "$B/client/mbopt" results "$job" --json --server "$address" || true; } |
        sed -nE 's/^  "analyses": *([0-9]+).*/\1/p')
    analyses=$((analyses + ${n:-0}))
  done
  rounds+=("$(printf "'%s'," "${jobs[@]}")")
done
end=$(date +%s.%N)
cpu_end=$(awk '{print $14 + $15}' "/proc/$server/stat")
stop_service  # the server holds its database exclusively
for ids in "${rounds[@]}"; do
  read -r n ms < <(sqlite3 -separator ' ' "$DIR/jobs.db" \
    "SELECT count(*), max(committed_unix_ms) - min(committed_unix_ms) FROM analyses WHERE job_id IN (${ids%,})")
  logged=$((logged + n)) logged_ms=$((logged_ms + ms))
done
awk -v a="$start" -v b="$end" -v n="$analyses" -v t=$((cpu_end - cpu_start)) -v hz="$TICKS" \
  -v jobs=$((IN_FLIGHT * ROUNDS)) -v w="$WORKERS" -v s="$SLOTS" 'BEGIN {
    printf "%d jobs, %d analyses in %.2f s on %d workers x %d slots: %.0f analyses/s; server CPU %.3f ms per analysis\n",
      jobs, n, b - a, w, s, n / (b - a), 1000 * t / hz / n }'
awk -v n="$logged" -v ms="$logged_ms" 'BEGIN { printf "while jobs run: %d analyses logged in %.2f s: %.0f analyses/s\n", n, ms / 1000, 1000 * n / ms }'
