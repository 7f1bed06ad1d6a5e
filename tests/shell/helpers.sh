# Helpers shared by the tests written as shell scripts (tests/multihost,
# tests/slurm, deploy/container/smoke_test.sh). Source it after setting
# TEST_NAME (the prefix of every message) and GUARD_S (the longest any one
# wait may take, in seconds: a failure guard, not a pace).

fail() {
  echo "$TEST_NAME: FAIL: $*" >&2
  exit 1
}

# Re-runs the calling script ("$@" are its arguments) as root through sudo
# when it is not root and sudo needs no password (a user the README's set-up
# allows); fails naming `why` root is needed otherwise.
run_as_root() {
  local why=$1
  shift
  [ "$(id -u)" -eq 0 ] && return 0
  sudo -n true 2> /dev/null || fail "$why needs root: run the tests as root or as a user with sudo"
  exec sudo -n bash "$0" "$@"
}

# Waits until the command "$@" succeeds; $1 says what is awaited.
wait_for() {
  local what=$1
  shift
  local deadline=$((SECONDS + GUARD_S))
  until "$@"; do
    [ $SECONDS -lt $deadline ] || fail "timed out waiting for $what"
    sleep 0.05
  done
}

# `mbopt results --json` (or `mbopt run --json`) on stdin, without the fields
# that differ between two runs of one study: what "the same result" means.
# Every double is printed with 17 significant digits, so equal text is equal
# bits.
#
# Who computed a job (its token holders, on a server with tokens) is not
# part of its result.
comparable() { sed '/"computed_by": {/,/}/d' | grep -v -e '"job_id":' -e '"database":' -e '"wall_seconds":'; }

# Fails, showing the difference, unless the comparable results $2 of the job
# named $1 equal the reference $3.
expect_same_result() {
  [ -n "$3" ] || fail "the reference run printed nothing"
  if [ "$2" != "$3" ]; then
    diff <(echo "$3") <(echo "$2") >&2 || true
    fail "$1 differs from the uninterrupted run"
  fi
}

# Sends TERM to the processes whose pid files are given and waits (at most
# 10 s) until they are gone. Daemons (slurmctld, slurmd, munged) are not
# this shell's children, so `wait` does not wait for them, and they write
# their state while shutting down: removing their directories before they
# are gone races with those writes.
stop_daemons() {
  local pidfile pid pids=()
  for pidfile in "$@"; do
    [ -f "$pidfile" ] || continue
    pid=$(cat "$pidfile" 2> /dev/null) || continue
    [ -n "$pid" ] && kill -TERM "$pid" 2> /dev/null && pids+=("$pid")
  done
  local deadline=$((SECONDS + 10))
  for pid in "${pids[@]}"; do
    while kill -0 "$pid" 2> /dev/null && [ $SECONDS -lt $deadline ]; do sleep 0.05; done
    kill -KILL "$pid" 2> /dev/null || true
  done
}

# Removes the test's directory $1 unless KEEP_LOGS=1. A directory that will
# not go (a straggler still writing) is reported, not turned into a failure
# of a test whose checks all passed.
remove_test_dir() {
  if [ "${KEEP_LOGS:-0}" = 1 ]; then
    echo "$TEST_NAME: logs in $1" >&2
    return 0
  fi
  rm -rf "$1" 2> /dev/null || { sleep 1; rm -rf "$1" 2> /dev/null; } \
    || echo "$TEST_NAME: note: could not remove $1" >&2
  return 0
}
