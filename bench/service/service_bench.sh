#!/usr/bin/env bash
# What the service itself costs, around the analyses (docs/benchmarks.md,
# "Service"). For each worker count W it runs STUDY JOBS times, one job at a
# time, on a fresh mbopt-server with W workers on 127.0.0.1, then reads the
# job database and prints medians over the jobs:
#   wall        the job's wall time (the server's measure)
#   analyses    analyses per job; work = the sum of their own wall times
#   per_s       analyses per second of job wall
#   efficiency  work / (W x wall): the share of the workers' time spent analysing
#   critical    cycles x (1 + ceil(n / W)) x the mean analysis time: one trial
#               point, then n finite-difference perturbations spread over W
#               workers, per cycle (n design variables). An estimate: the
#               analyses of a cycle do not all take the mean time.
#   overhead    (wall - critical) / cycles: what the service adds per cycle
#   server_cpu  the server's CPU time (user + system) per analysis, over the
#               whole run of that W (start and stop included)
#   latency     p50 and p99 over every analysis of that W of the time from its
#               task's queueing on the server to its result's arrival there
#               (analyses.latency_seconds): the analysis itself, the round
#               trips and the wait for a free worker
#
#   bash bench/service/service_bench.sh [STUDY] [JOBS] [W...]
# Defaults: the vehicle, 7 jobs, W = 1 2 4. SERVER_ARGS (environment) is
# passed to mbopt-server, e.g. SERVER_ARGS="--durability normal", and
# WORKER_ARGS to each mbopt-worker. Over TLS with tokens (an init-tls
# directory D): SERVER_ARGS="--tls-dir D" WORKER_ARGS="--token-file
# D/worker.token" MBOPT_TLS_CA=D/ca.pem MBOPT_TOKEN_FILE=D/admin.token.
set -euo pipefail
cd "$(dirname "$0")/../.."
STUDY=${1:-examples/vehicle/vehicle.study.textproto}
JOBS=${2:-7}
shift $(( $# >= 2 ? 2 : $# ))
WORKER_COUNTS=("$@")
[ ${#WORKER_COUNTS[@]} -eq 0 ] && WORKER_COUNTS=(1 2 4)
B=build
command -v sqlite3 > /dev/null || { echo "service_bench: needs the sqlite3 shell (deploy/install-deps.sh)" >&2; exit 1; }
DIR=$(mktemp -d)
trap 'pkill -P $$ 2>/dev/null || true; rm -rf "$DIR"' EXIT
TICKS=$(getconf CLK_TCK)
# shellcheck source=bench/loopback.sh
source bench/loopback.sh

median() { sort -g | awk '{a[NR]=$1} END {print (NR%2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}'; }

printf '%-3s %8s %9s %8s %7s %10s %9s %9s %11s %8s %8s\n' W wall_s analyses work_s per_s efficiency critical_s overhead_ms \
  server_cpu_ms lat50_ms lat99_ms
for W in "${WORKER_COUNTS[@]}"; do
  # shellcheck disable=SC2086  # SERVER_ARGS is a list of words
  start_server ${SERVER_ARGS:-}
  server=$SERVER_PID address=$ADDRESS
  # shellcheck disable=SC2086  # WORKER_ARGS is a list of words
  start_workers "$W" ${WORKER_ARGS:-}
  sleep 0.5  # the workers register
  for _ in $(seq "$JOBS"); do
    job=$("$B/client/mbopt" submit "$STUDY" --server "$address")
    "$B/client/mbopt" watch "$job" --server "$address" > /dev/null || true
  done
  cpu_ticks=$(awk '{print $14 + $15}' "/proc/$server/stat")
  stop_service
  # One line per job: wall, cycles, analyses, work, variables.
  sqlite3 -separator ' ' "$DIR/jobs.db" \
    "SELECT j.wall_seconds, j.cycles, count(a.request_id), sum(a.wall_seconds), max(length(a.x_scaled)) / 8
       FROM jobs j JOIN analyses a ON a.job_id = j.id GROUP BY j.id" > "$DIR/jobs.txt"
  total_analyses=$(awk '{n += $3} END {print n}' "$DIR/jobs.txt")
  awk -v W="$W" '{
      wall = $1; cycles = $2; n_an = $3; work = $4; n = $5
      mean = work / n_an; per_cycle = 1 + int((n + W - 1) / W)
      critical = cycles * per_cycle * mean
      print wall, n_an, work, n_an / wall, work / (W * wall), critical, 1000 * (wall - critical) / cycles
    }' "$DIR/jobs.txt" > "$DIR/derived.txt"
  cols=()
  for c in 1 2 3 4 5 6 7; do cols+=("$(awk -v c=$c '{print $c}' "$DIR/derived.txt" | median)"); done
  sqlite3 "$DIR/jobs.db" "SELECT latency_seconds FROM analyses ORDER BY latency_seconds" > "$DIR/latency.txt"
  percentile() { awk -v p="$1" '{a[NR]=$1} END {i = int(p * NR + 0.999999); if (i < 1) i = 1; print 1000 * a[i]}' "$DIR/latency.txt"; }
  printf '%-3s %8.3f %9.0f %8.3f %7.0f %10.2f %9.3f %9.1f %11.3f %8.2f %8.2f\n' "$W" "${cols[@]}" \
    "$(awk -v t="$cpu_ticks" -v hz="$TICKS" -v n="$total_analyses" 'BEGIN {print 1000 * t / hz / n}')" \
    "$(percentile 0.50)" "$(percentile 0.99)"
done
