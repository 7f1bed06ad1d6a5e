#!/usr/bin/env bash
# Workers under a real Slurm: a single-node cluster on this machine (Debian's
# slurmctld, slurmd and munge, installed by deploy/install-deps.sh) with a
# configuration, state and munge key of its own in a temporary directory,
# torn down at the end. The server listens on loopback with TLS and tokens.
#
#  1. The worker array deploy/slurm/mbopt-workers.sbatch is submitted with
#     sbatch and the job runs.
#  2. In the middle of the job the array is scancel'ed: the job waits,
#     still running, with no workers.
#  3. The same array is submitted again; the job converges.
#  4. Its result equals that of an uninterrupted `mbopt run`, bit for bit
#     (every double of the history and the design, printed with 17 digits).
#
# Needs root (slurmd runs jobs as their user, munged's key).
#
#   bash tests/slurm/slurm_test.sh MBOPT_SERVER MBOPT_WORKER MBOPT
set -euo pipefail
SERVER_BIN=$1 WORKER_BIN=$2 MBOPT_BIN=$3
cd "$(dirname "$0")/../.."
ROOT=$(pwd)
STUDY=examples/vehicle/vehicle.study.textproto
DELAY_MS=300
GUARD_S=120
TEST_NAME=slurm
# shellcheck source=tests/shell/helpers.sh
source tests/shell/helpers.sh
run_as_root "a private Slurm cluster" "$@"
for tool in slurmctld slurmd sbatch squeue scancel sinfo munged mungekey; do
  command -v "$tool" > /dev/null || fail "needs $tool (slurmctld, slurmd, slurm-client and munge: deploy/install-deps.sh)"
done

DIR=$(mktemp -d)
chmod 755 "$DIR"
cleanup() {
  if [ -n "${SLURM_CONF:-}" ]; then
    scancel --quiet --name=mbopt-workers 2> /dev/null || true
    # Job steps write their output into $DIR until they end.
    local deadline=$((SECONDS + 10))
    while [ -n "$(squeue -h --name=mbopt-workers 2> /dev/null)" ] && [ $SECONDS -lt $deadline ]; do sleep 0.1; done
  fi
  [ -n "${SERVER_PID:-}" ] && kill -TERM "$SERVER_PID" 2> /dev/null || true
  stop_daemons "$DIR"/run/slurmd.pid "$DIR"/run/slurmctld.pid
  stop_daemons "$DIR"/run/munged.pid
  wait 2> /dev/null || true
  remove_test_dir "$DIR"
}
trap cleanup EXIT

# munge: its own key and socket, so nothing of the machine's is used.
mkdir -p "$DIR/munge" "$DIR/run" "$DIR/state" "$DIR/spool" "$DIR/log"
mungekey --create --keyfile="$DIR/munge/munge.key" 2> /dev/null || fail "mungekey could not make a key"
munged --force --socket="$DIR/munge/munge.sock" --key-file="$DIR/munge/munge.key" \
  --pid-file="$DIR/run/munged.pid" --log-file="$DIR/log/munged.log" --seed-file="$DIR/munge/munge.seed" \
  || fail "munged did not start ($(tail -3 "$DIR/log/munged.log" 2> /dev/null))"

# Slurm: one node (this machine, reached on loopback), one partition, ports
# of its own. The node's name must be this machine's short host name.
node=$(hostname -s)
# Below the kernel's ephemeral range (32768 and up), where ports chosen for
# outgoing connections and "port 0" listeners could take them first.
port=$((20000 + ($$ % 6000) * 2))
cat > "$DIR/slurm.conf" << CONF
ClusterName=mbopttest
SlurmctldHost=$node(127.0.0.1)
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$DIR/munge/munge.sock
CredType=cred/munge
StateSaveLocation=$DIR/state
SlurmdSpoolDir=$DIR/spool
SlurmctldPidFile=$DIR/run/slurmctld.pid
SlurmdPidFile=$DIR/run/slurmd.pid
SlurmctldLogFile=$DIR/log/slurmctld.log
SlurmdLogFile=$DIR/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
MpiDefault=none
ReturnToService=2
KillWait=5
NodeName=$node NodeAddr=127.0.0.1 CPUs=$(nproc) State=UNKNOWN
PartitionName=mbopt Nodes=$node Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF="$DIR/slurm.conf"
slurmctld -f "$SLURM_CONF" || fail "slurmctld did not start: $(tail -5 "$DIR/log/slurmctld.log")"
slurmd -f "$SLURM_CONF" || fail "slurmd did not start: $(tail -5 "$DIR/log/slurmd.log")"
node_idle() { sinfo -h -N -o %t 2> /dev/null | grep -qx idle; }
wait_for "the Slurm node to be idle" node_idle

# The server, on loopback with TLS and tokens.
"$SERVER_BIN" init-tls "$DIR/pki" --host 127.0.0.1 --user alice > /dev/null
"$SERVER_BIN" --listen 127.0.0.1:0 --port-file "$DIR/port" --tls-dir "$DIR/pki" --db "$DIR/jobs.db" \
  > "$DIR/server.out" 2> "$DIR/server.err" &
SERVER_PID=$!
wait_for "the server to listen" test -s "$DIR/port"
address="127.0.0.1:$(cat "$DIR/port")"
as_alice() { MBOPT_TLS_CA="$DIR/pki/ca.pem" MBOPT_TOKEN_FILE="$DIR/pki/alice.token" "$MBOPT_BIN" "$@" --server "$address"; }

# The worker array, exactly as deploy/slurm ships it: only the size, the
# cores and the log directory are overridden, and the worker binary comes
# first on PATH. Options after the script go to mbopt-worker.
submit_array() {
  PATH="$(dirname "$WORKER_BIN"):$PATH" MBOPT_SERVER="$address" MBOPT_TLS_CA="$DIR/pki/ca.pem" \
    MBOPT_TOKEN_FILE="$DIR/pki/worker.token" \
    sbatch --parsable --array=0-1 --cpus-per-task=1 --output="$DIR/worker-%A_%a.log" \
      "$ROOT/deploy/slurm/mbopt-workers.sbatch" --verbose --task-delay-ms "$DELAY_MS"
}
analyses_done() { cat "$DIR"/worker-*.log 2> /dev/null | grep -c ' ok$' || true; }
array_gone() { [ -z "$(squeue -h -j "$1" 2> /dev/null)" ]; }

array=$(submit_array)
job=$(as_alice submit "$STUDY")
wait_for "the array's workers to analyse" eval '[ "$(analyses_done)" -ge 8 ]'
scancel "$array"
wait_for "the array to end after scancel" array_gone "$array"
done_before=$(analyses_done)
state=$(as_alice results "$job" --json | sed -nE 's/^  "status": "([a-z_]+)".*/\1/p')
echo "slurm: array $array cancelled after $done_before analyses; the job is $state" >&2
[ "$state" = running ] || fail "the job was not in its middle when the array was cancelled: $state"

array=$(submit_array)
as_alice watch "$job" > /dev/null || fail "$job did not converge after the array was submitted again"
scancel "$array"

reference=$("$MBOPT_BIN" run "$STUDY" --json --workers 2 --discard-db | comparable)
expect_same_result "$job" "$(as_alice results "$job" --json | comparable)" "$reference"
echo "slurm: ok: $job converged under two worker arrays ($(analyses_done) analyses logged by them), identical to an uninterrupted run" >&2
