#!/usr/bin/env bash
# Re-analyses an optimized design on finer time grids: the optimizer saw the
# stress (or any time-dependent constraint) only at the study's grid instants,
# so a peak between them could exceed the limit unseen. Each recheck is a full
# analysis (`mbopt-worker eval`) of a copy of the study with
# `analysis { time_grid_points: N }`; the design is taken from the job's
# `results --json` (or `run --json`) document.
#
# usage: examples/fourbar/recheck_grid.sh STUDY RESULTS_JSON [POINTS ...]
#   POINTS default: 101 1001. mbopt-worker: $MBOPT_WORKER_BIN, else
#   build/worker/main/mbopt-worker.
# Prints, per grid: points, objective, largest normalized constraint value
# (> 0 violated) and the worst row. Exit status 1 if any grid finds a
# violation above 1e-4 (0.01 %), 0 otherwise.
set -euo pipefail
if [[ $# -lt 2 ]]; then
  sed -n '2,15p' "$0" >&2
  exit 2
fi
study=$(realpath "$1")
results=$2
shift 2
grids=("$@")
[[ ${#grids[@]} -gt 0 ]] || grids=(101 1001)
root=$(cd "$(dirname "$0")/../.." && pwd)
worker=${MBOPT_WORKER_BIN:-$root/build/worker/main/mbopt-worker}

# --set NAME=VALUE for every design variable, in the study's scaled units.
mapfile -t sets < <(python3 -c '
import json, sys
d = json.load(open(sys.argv[1]))
# Without design_scaled (a document from an older client) take the scaled design
# of the last accepted cycle, which is the design of the job.
scaled = d.get("design_scaled") or dict(zip(d["design"], d["history"][-1]["x_scaled"]))
for name, x in scaled.items():
    print("--set")
    print("%s=%.17g" % (name, x))
' "$results")

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
scene_dir=$(dirname "$study")
status=0
for n in "${grids[@]}"; do
  copy="$tmp/grid$n.study.textproto"
  # The copy lives elsewhere: its scene_file must be absolute. Its grid is
  # N points: set in the study's one-line `analysis { ... }` block if it has
  # one, else in a new block.
  python3 -c '
import re, sys
study, scene_dir, n = sys.argv[1], sys.argv[2], sys.argv[3]
text = open(study).read()
text = re.sub(r"^scene_file: \"([^/][^\"]*)\"", lambda m: "scene_file: \"%s/%s\"" % (scene_dir, m.group(1)), text, flags=re.M)
block = re.search(r"^analysis \{(.*)\}\s*$", text, flags=re.M)
if block is None:
    text += "\nanalysis { time_grid_points: %s }\n" % n
else:
    inner = re.sub(r"\s*time_grid_points:\s*\d+", "", block.group(1))
    text = text[:block.start()] + "analysis { time_grid_points: %s%s}" % (n, inner.rstrip() + " ") + text[block.end():]
    text += "\n"
print(text, end="")
' "$study" "$scene_dir" "$n" > "$copy"
  "$worker" eval "$copy" "${sets[@]}" --json > "$tmp/eval$n.json"
  python3 -c '
import json, sys
d = json.load(open(sys.argv[1]))
w = d.get("worst_constraint") or {}
print("grid %5s points: objective %.6g %s, max violation %+.3e, worst %s" % (
    sys.argv[2], d["objective"], d.get("objective_unit", ""), d["max_violation"], w.get("name", "-")))
sys.exit(1 if d["status"] != "ok" or d["max_violation"] > 1e-4 else 0)
' "$tmp/eval$n.json" "$n" || status=1
done
exit $status
