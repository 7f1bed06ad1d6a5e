#!/usr/bin/env bash
# Load and soak on loopback (docs/reliability.md, "Load and soak"): one
# server, WORKERS workers, JOBS jobs of STUDY submitted IN_FLIGHT at a time.
# Every CHECK jobs it prints the jobs finished, the analyses per second since
# the start, the server's resident memory (VmRSS) and the job database's
# size (with its WAL). At the end every job's result must equal the first
# job's (`results --json` without job id and wall times): a difference, a
# job that did not end converged, or a server that died is an error (exit 1).
#
#   bash bench/reliability/soak.sh [JOBS] [IN_FLIGHT] [WORKERS] [STUDY] [CHECK]
#
# SOAK_SERVER_ARGS adds options to mbopt-server, e.g. admission limits:
#   SOAK_SERVER_ARGS="--max-running-jobs 4" bash bench/reliability/soak.sh 200 200 2
set -euo pipefail
cd "$(dirname "$0")/../.."
JOBS=${1:-1000}
IN_FLIGHT=${2:-8}
WORKERS=${3:-2}
STUDY=${4:-examples/vehicle/vehicle.study.textproto}
CHECK=${5:-100}
B=build
DIR=$(mktemp -d)
trap 'pkill -P $$ 2>/dev/null || true; rm -rf "$DIR"' EXIT

# shellcheck source=bench/loopback.sh
source bench/loopback.sh
read -r -a server_args <<< "${SOAK_SERVER_ARGS:-}"
start_server "${server_args[@]}"
server=$SERVER_PID address=$ADDRESS
start_workers "$WORKERS"
mbopt() { "$B/client/mbopt" "$@" --server "$address"; }
rss_mb() { awk '/^VmRSS:/ {printf "%.1f", $2 / 1024}' "/proc/$server/status"; }
db_mb() { du -cb "$DIR"/jobs.db* | awk 'END {printf "%.1f", $1 / 1e6}'; }
# The result without what differs between runs of the same study.
comparable() { sed -E 's/"job_id": *"[^"]*",?//g; s/"wall_seconds": *[-0-9.eE+]*,?//g'; }

start=$(date +%s.%N)
elapsed() { awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN {print b - a}'; }
echo "jobs  seconds  analyses/s  server_rss_MB  db_MB"
printf '%4d  %7.1f  %10s  %13s  %5s\n' 0 0 - "$(rss_mb)" "$(db_mb)"
done_jobs=0 analyses=0
reference=""
while [ "$done_jobs" -lt "$JOBS" ]; do
  batch=()
  for _ in $(seq "$IN_FLIGHT"); do
    [ $((done_jobs + ${#batch[@]})) -ge "$JOBS" ] && break
    batch+=("$(mbopt submit "$STUDY")")
  done
  for job in "${batch[@]}"; do
    mbopt watch "$job" > /dev/null || { echo "soak: $job did not converge" >&2; exit 1; }
    result=$(mbopt results "$job" --json)
    n=$(printf '%s' "$result" | sed -nE 's/.*"analyses": *([0-9]+).*/\1/p' | head -1)
    analyses=$((analyses + n))
    result=$(printf '%s' "$result" | comparable)
    if [ -z "$reference" ]; then
      reference=$result
    elif [ "$result" != "$reference" ]; then
      echo "soak: $job differs from the first job" >&2
      diff <(printf '%s\n' "$reference") <(printf '%s\n' "$result") | head >&2
      exit 1
    fi
    done_jobs=$((done_jobs + 1))
    if [ $((done_jobs % CHECK)) -eq 0 ] || [ "$done_jobs" -eq 10 ] || [ "$done_jobs" -eq "$JOBS" ]; then
      kill -0 "$server" || { echo "soak: the server died" >&2; exit 1; }
      seconds=$(elapsed)
      printf '%4d  %7.1f  %10.0f  %13s  %5s\n' "$done_jobs" "$seconds" \
        "$(awk -v n="$analyses" -v s="$seconds" 'BEGIN {print n / s}')" "$(rss_mb)" "$(db_mb)"
    fi
  done
done
echo "soak: $done_jobs jobs, every result identical to the first"
