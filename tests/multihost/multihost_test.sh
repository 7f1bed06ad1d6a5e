#!/usr/bin/env bash
# Several hosts, simulated with Linux network namespaces this test makes
# (and deletes): the server in one, three workers in three others, each
# worker joined to the server by its own veth pair and subnet (10.231.N.0/24,
# which exists only inside these namespaces). Everything runs over TLS with
# tokens, as deploy/README.md sets it up with `mbopt-server init-tls`.
#
#  1. Two workers run two jobs of the vehicle study.
#  2. Worker 1's link is cut just after it finished an analysis and before
#     it reported it: that lease expires and the task goes to worker 2.
#  3. The link is healed (worker 1 gets work again) and worker 3 joins in the
#     middle of the jobs (it gets work).
#  4. Both jobs end with the result of an uninterrupted run (`mbopt run` on
#     loopback), field for field, and the database shows a task that was
#     leased twice.
#
# Workers hold each result for a while (--task-delay-ms) so that there is a
# middle of the job to act in. Needs root (network namespaces) and iproute2.
#
#   bash tests/multihost/multihost_test.sh MBOPT_SERVER MBOPT_WORKER MBOPT
set -euo pipefail
SERVER_BIN=$1 WORKER_BIN=$2 MBOPT_BIN=$3
cd "$(dirname "$0")/../.."
STUDY=examples/vehicle/vehicle.study.textproto
LEASE_MS=2000
DELAY_MS=500
GUARD_S=120
TEST_NAME=multihost
# shellcheck source=tests/shell/helpers.sh
source tests/shell/helpers.sh
run_as_root "making network namespaces" "$@"
command -v ip > /dev/null || fail "needs ip from iproute2 (deploy/install-deps.sh installs it)"
command -v sqlite3 > /dev/null || fail "needs the sqlite3 shell (deploy/install-deps.sh installs it)"

tag="mb$$"
SRV="$tag-srv"
WORKER_NS=("$tag-w1" "$tag-w2" "$tag-w3")
DIR=$(mktemp -d)
PIDS=()
cleanup() {
  for pid in "${PIDS[@]}"; do kill -9 "$pid" 2> /dev/null || true; done
  wait 2> /dev/null || true
  for ns in "$SRV" "${WORKER_NS[@]}"; do ip netns del "$ns" 2> /dev/null || true; done
  remove_test_dir "$DIR"
}
trap cleanup EXIT

# The network: one namespace per host, a veth pair per worker.
ip netns add "$SRV" || fail "cannot make a network namespace (ip netns add): this machine does not allow it"
ip -n "$SRV" link set lo up
for i in 1 2 3; do
  ns=${WORKER_NS[$((i - 1))]}
  ip netns add "$ns"
  ip -n "$ns" link set lo up
  ip link add "$tag-s$i" netns "$SRV" type veth peer name "$tag-w$i" netns "$ns"
  ip -n "$SRV" addr add "10.231.$i.1/24" dev "$tag-s$i"
  ip -n "$SRV" link set "$tag-s$i" up
  ip -n "$ns" addr add "10.231.$i.2/24" dev "$tag-w$i"
  ip -n "$ns" link set "$tag-w$i" up
done
# The host's own namespace has no route to these addresses.
! ip route get 10.231.1.1 2> /dev/null | grep -q "dev $tag" || fail "10.231.1.1 is reachable from the host"

tasks_done() { grep -c ' ok$' "$DIR/w$1.log" 2> /dev/null || true; }
at_least() { [ "$(tasks_done "$1")" -ge "$2" ]; }

# The secure installation, for the server's three addresses.
"$SERVER_BIN" init-tls "$DIR/pki" --host 10.231.1.1 --host 10.231.2.1 --host 10.231.3.1 --user alice > /dev/null
ip netns exec "$SRV" "$SERVER_BIN" --listen 0.0.0.0:50051 --tls-dir "$DIR/pki" --db "$DIR/jobs.db" \
  --lease-ms "$LEASE_MS" > "$DIR/server.out" 2> "$DIR/server.err" &
SERVER_PID=$!
PIDS+=("$SERVER_PID")
wait_for "the server to listen" grep -q "listening on" "$DIR/server.out"

start_worker() {
  local i=$1
  ip netns exec "${WORKER_NS[$((i - 1))]}" "$WORKER_BIN" serve --server "10.231.$i.1:50051" --name "w$i" \
    --tls-ca "$DIR/pki/ca.pem" --token-file "$DIR/pki/worker.token" --verbose --task-delay-ms "$DELAY_MS" \
    2> "$DIR/w$i.log" &
  PIDS+=($!)
}
# The user's commands run in the server's namespace, reaching it over TLS.
as_alice() {
  ip netns exec "$SRV" env MBOPT_TLS_CA="$DIR/pki/ca.pem" MBOPT_TOKEN_FILE="$DIR/pki/alice.token" \
    "$MBOPT_BIN" "$@" --server 10.231.1.1:50051
}

start_worker 1
start_worker 2
jobs=("$(as_alice submit "$STUDY")" "$(as_alice submit "$STUDY")")
wait_for "both workers to work" eval 'at_least 1 2 && at_least 2 2'

# Cut worker 1 off right after it logged an analysis, which it then holds
# for DELAY_MS before reporting.
done1=$(tasks_done 1)
wait_for "worker 1's next analysis" at_least 1 $((done1 + 1))
ip -n "$SRV" link set "$tag-s1" down
echo "multihost: cut worker 1 after $(tasks_done 1) analyses" >&2
# The others go on without it, past its lease.
done2=$(tasks_done 2)
wait_for "worker 2 to go on alone" at_least 2 $((done2 + (LEASE_MS / DELAY_MS) + 2))

# Heal the link; worker 3 joins.
done1=$(tasks_done 1)
ip -n "$SRV" link set "$tag-s1" up
start_worker 3
wait_for "worker 1 to work again after the link came back" at_least 1 $((done1 + 1))
wait_for "worker 3 to get work" at_least 3 1
echo "multihost: worker 1 rejoined, worker 3 joined ($(tasks_done 1), $(tasks_done 2), $(tasks_done 3) analyses)" >&2

for job in "${jobs[@]}"; do
  as_alice watch "$job" > /dev/null || fail "$job did not converge (mbopt watch exit $?)"
done

reference=$("$MBOPT_BIN" run "$STUDY" --json --workers 2 --discard-db | comparable)
for job in "${jobs[@]}"; do
  expect_same_result "$job" "$(as_alice results "$job" --json | comparable)" "$reference"
done
# The server holds its database locked while it runs.
kill -TERM "$SERVER_PID"
wait "$SERVER_PID" || fail "the server did not stop cleanly on SIGTERM"
releases=$(sqlite3 "$DIR/jobs.db" "SELECT count(*) FROM analyses WHERE attempts > 1")
[ "$releases" -ge 1 ] || fail "no task was leased twice: the cut did not catch worker 1 holding one"
by_worker=$(sqlite3 "$DIR/jobs.db" "SELECT group_concat(worker || ':' || n, ' ') FROM (SELECT worker, count(*) AS n FROM analyses GROUP BY worker)")
for pid in "${PIDS[@]}"; do kill -TERM "$pid" 2> /dev/null || true; done
wait 2> /dev/null || true
echo "multihost: ok: ${#jobs[@]} jobs identical to the uninterrupted run; $releases tasks leased twice; analyses by worker: $by_worker" >&2
