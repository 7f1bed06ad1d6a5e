#!/usr/bin/env bash
# The cost of a worker killed with a task in hand (docs/reliability.md).
# Runs STUDY (default: the vehicle) TRIALS times (default 5) on a fresh
# server on 127.0.0.1 with the default 30 s lease and two workers, once with
# both healthy and once with the second killed (SIGKILL, from inside, via
# --die-after-tasks) after KILL_AFTER tasks (default 20), and prints the
# jobs' wall times and their medians. A third worker is started when the
# second dies, so both runs end with two workers.
#
#   bash bench/reliability/worker_kill.sh [STUDY] [TRIALS] [KILL_AFTER]
set -euo pipefail
cd "$(dirname "$0")/../.."
STUDY=${1:-examples/vehicle/vehicle.study.textproto}
TRIALS=${2:-5}
KILL_AFTER=${3:-20}
B=build
DIR=$(mktemp -d)
trap 'pkill -P $$ 2>/dev/null || true; rm -rf "$DIR"' EXIT
# shellcheck source=bench/loopback.sh
source bench/loopback.sh

one_run() {  # $1: normal | killed; prints the job's wall seconds
  start_server
  local server=$SERVER_PID address=$ADDRESS
  "$B/worker/main/mbopt-worker" serve --server "$address" --name steady 2> /dev/null &
  local pids=($!)
  if [ "$1" = killed ]; then
    ( exec 2> /dev/null  # bash's own "Killed" notice
      "$B/worker/main/mbopt-worker" serve --server "$address" --name doomed --die-after-tasks "$KILL_AFTER" \
        2> /dev/null || true
      exec "$B/worker/main/mbopt-worker" serve --server "$address" --name replacement 2> /dev/null ) &
  else
    "$B/worker/main/mbopt-worker" serve --server "$address" --name second 2> /dev/null &
  fi
  pids+=($!)
  local job
  job=$("$B/client/mbopt" submit "$STUDY" --server "$address")
  "$B/client/mbopt" watch "$job" --server "$address" > /dev/null || true
  "$B/client/mbopt" status "$job" --server "$address" | awk '/wall time:/ {print $3}'
  pkill -f "mbopt-worker serve --server $address" || true
  kill "$server"
  wait 2> /dev/null || true
}

median() { sort -g | awk '{a[NR]=$1} END {print (NR%2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}'; }

declare -A walls
for mode in normal killed; do walls[$mode]=""; done
for trial in $(seq "$TRIALS"); do
  for mode in normal killed; do
    w=$(one_run "$mode")
    echo "trial $trial $mode: job wall $w s"
    walls[$mode]+="$w"$'\n'
  done
done
n=$(printf '%s' "${walls[normal]}" | median)
k=$(printf '%s' "${walls[killed]}" | median)
echo "median job wall: $n s healthy, $k s with a worker killed; extra $(awk -v a="$k" -v b="$n" 'BEGIN {printf "%.2f", a-b}') s"
