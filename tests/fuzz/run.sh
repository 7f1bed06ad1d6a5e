#!/usr/bin/env bash
# Builds the fuzzing targets (clang, libFuzzer, AddressSanitizer,
# UndefinedBehaviorSanitizer) into ./build-fuzz and runs each for a bounded
# time, seeded with the example studies and every kept finding.
#   tests/fuzz/run.sh                       20 s per target (what the test command runs)
#   tests/fuzz/run.sh --seconds 1200        longer, on demand
#   tests/fuzz/run.sh --target study_text --seconds 3600 --jobs 2
# A finding (crash, failed check, hang over 10 s, over 4 GB) stops its
# target and is written to build-fuzz/findings/TARGET/; once fixed, keep it
# under tests/fuzz/regressions/TARGET/ (fuzz_regression_test replays it).
set -euo pipefail
cd "$(dirname "$0")/../.."
seconds=20
targets=(study_text scene_text study_binary packed_values result_intake)
jobs=1
while [[ $# -gt 0 ]]; do
  case "$1" in
    --seconds) seconds="$2"; shift 2 ;;
    --target) targets=("$2"); shift 2 ;;
    --jobs) jobs="$2"; shift 2 ;;
    *) echo "usage: tests/fuzz/run.sh [--seconds N] [--target study_text|scene_text|study_binary|packed_values|result_intake] [--jobs N]" >&2; exit 2 ;;
  esac
done
build=build-fuzz
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ -DMBOPT_FUZZ=ON \
  > "$build.configure.log" 2>&1 || { cat "$build.configure.log"; exit 1; }
rm -f "$build.configure.log"
cmake --build "$build" --parallel "$(nproc)" --target make_fuzz_seeds "${targets[@]/%/_fuzzer}"
seeds="$build/seeds"
rm -rf "$seeds"
"$build/tests/fuzz/make_fuzz_seeds" "$seeds" examples/*/*.study.textproto
status=0
for target in "${targets[@]}"; do
  corpus="$build/corpus/$target" findings="$build/findings/$target"
  mkdir -p "$corpus" "$findings" "$seeds/$target"
  extra=()
  [[ "$jobs" -gt 1 ]] && extra+=(-jobs="$jobs" -workers="$jobs")
  [[ -d "tests/fuzz/regressions/$target" ]] && extra+=("tests/fuzz/regressions/$target")
  echo "fuzz: $target for ${seconds} s"
  if ! "$build/tests/fuzz/${target}_fuzzer" "$corpus" "$seeds/$target" "${extra[@]}" \
      -max_total_time="$seconds" -timeout=10 -rss_limit_mb=4096 \
      -artifact_prefix="$findings/" -print_final_stats=1 > "$build/$target.log" 2>&1; then
    tail -40 "$build/$target.log"
    echo "fuzz: $target found an input that fails (saved in $findings/)" >&2
    status=1
  else
    grep -E "^(stat::number_of_executed_units|stat::new_units_added|Done)" "$build/$target.log" || tail -3 "$build/$target.log"
  fi
done
exit $status
