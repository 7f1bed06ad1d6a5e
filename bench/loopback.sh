# Sourced by the benchmark scripts: an mbopt-server on 127.0.0.1 with a
# fresh database in DIR, and its workers. Needs B (the build directory) and
# DIR (a scratch directory) set.
#   start_server [SERVER ARGS...]   sets SERVER_PID and ADDRESS once it listens
#   start_workers N [WORKER ARGS...] N workers named w1..wN on ADDRESS
#   stop_service                    the workers, then the server (SIGTERM)

start_server() {
  rm -f "$DIR"/jobs.db* "$DIR/port"
  "$B/server/main/mbopt-server" --listen 127.0.0.1:0 --db "$DIR/jobs.db" --port-file "$DIR/port" "$@" \
    > /dev/null 2> "$DIR/server.log" &
  SERVER_PID=$!
  while [ ! -s "$DIR/port" ]; do
    kill -0 "$SERVER_PID" 2> /dev/null || { cat "$DIR/server.log" >&2; return 1; }
    sleep 0.05
  done
  ADDRESS="127.0.0.1:$(cat "$DIR/port")"
}

start_workers() {
  local n=$1
  shift
  for i in $(seq "$n"); do
    "$B/worker/main/mbopt-worker" serve --server "$ADDRESS" --name "w$i" "$@" 2> /dev/null &
  done
}

stop_service() {
  pkill -f "mbopt-worker serve --server $ADDRESS" || true
  kill "$SERVER_PID" 2> /dev/null || true
  wait "$SERVER_PID" 2> /dev/null || true
}
