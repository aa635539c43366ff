#!/bin/bash
# Runs the libFuzzer targets of tests/fuzz for a given time each and prints their figures
# (docs/FUZZING.md records a run).
#
#   tests/fuzz/run-fuzzers.sh [SECONDS] [TARGET...]      (default 600 s, every target)
#
# Builds the clang fuzz build first (BUILD_DIR, default build-fuzz beside this repository's
# source; SOURCE_DIR overrides the source tree). Each target starts from its committed seed
# corpus (tests/fuzz/corpus/<target>, never written to) and a work corpus
# (<OUT_DIR>/<target>/corpus, default OUT_DIR = BUILD_DIR/fuzz-runs) where it keeps what it
# finds; crashes, leaks, timeouts and out-of-memory inputs land in <OUT_DIR>/<target>/artifacts.
# Limits: -rss_limit_mb=$RSS_MB (default 2048), -timeout=$TIMEOUT s per input (default 10).
# The exit status is 1 when any target left an artifact.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
source_dir=${SOURCE_DIR:-$(cd "$here/../.." && pwd)}
build=${BUILD_DIR:-$source_dir/build-fuzz}
out=${OUT_DIR:-$build/fuzz-runs}
rss_mb=${RSS_MB:-2048}
timeout_s=${TIMEOUT:-10}
seconds=${1:-600}
[ $# -gt 0 ] && shift
targets=("$@")
[ ${#targets[@]} -eq 0 ] && targets=(fuzz_dbc_parser fuzz_candump fuzz_chunk fuzz_request)

if [ ! -f "$build/CMakeCache.txt" ]; then
  CC=clang CXX=clang++ cmake -S "$source_dir" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DDYNID_FUZZ=ON -DDYNID_BUILD_BENCHMARKS=OFF
fi
cmake --build "$build" -j2 --target "${targets[@]}"

found=0
printf '%-16s %8s %12s %8s %6s %7s %12s %9s\n' target seconds execs exec/s cov ft corpus findings
for target in "${targets[@]}"; do
  work="$out/$target"
  mkdir -p "$work/corpus" "$work/artifacts"
  dict=()
  [ -f "$here/$target.dict" ] && dict=(-dict="$here/$target.dict")
  start=$(date +%s)
  status=0
  "$build/tests/fuzz/$target" -max_total_time="$seconds" -rss_limit_mb="$rss_mb" \
    -timeout="$timeout_s" -print_final_stats=1 -artifact_prefix="$work/artifacts/" \
    "${dict[@]}" "$work/corpus" "$here/corpus/$target" > "$work/log" 2>&1 || status=$?
  elapsed=$(( $(date +%s) - start ))
  # The last status line ("#N ... cov: C ft: F corp: U/S ... exec/s: E") and the final stats.
  last=$(grep -E '^#[0-9]+' "$work/log" | tail -1)
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$work/log")
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$work/log")
  cov=$(sed -n 's/.* cov: \([0-9]*\).*/\1/p' <<< "$last")
  ft=$(sed -n 's/.* ft: \([0-9]*\).*/\1/p' <<< "$last")
  corp=$(sed -n 's/.* corp: \([^ ]*\).*/\1/p' <<< "$last")
  artifacts=$(find "$work/artifacts" -type f | wc -l)
  [ "$status" -ne 0 ] || [ "$artifacts" -ne 0 ] && found=1
  printf '%-16s %8s %12s %8s %6s %7s %12s %9s\n' "$target" "$elapsed" "${execs:-?}" "${rate:-?}" \
    "${cov:-?}" "${ft:-?}" "${corp:-?}" "$artifacts (exit $status)"
done
exit $found
