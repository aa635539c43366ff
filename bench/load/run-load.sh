#!/usr/bin/env bash
# The end-to-end load benchmark (issue 7): dynid-server on a temporary store, N simulated
# vehicles (dynid-load) over Cyclone DDS on loopback (deploy/cyclonedds/loopback.xml, a
# discovery tag of this run), and Cyclone's ddsperf for the same payload on the same
# configuration in the same run, as the transport's limit. docs/BENCHMARKS.md ("Load") explains
# the figures.
#
#   bash bench/load/run-load.sh [table]   ddsperf, then for each N: REPS fast runs (as fast as
#                                         the acks allow) and REPS paced runs (RATE Hz per
#                                         vehicle, real time); a table of medians (< 15 min)
#   bash bench/load/run-load.sh soak      SOAK_VEHICLES paced for SOAK_SECONDS (600), the
#                                         server's RSS every 5 s, its slope
#   bash bench/load/run-load.sh smoke     10 vehicles, a few seconds: correctness only (ctest)
#
# Environment: BUILD_DIR (build-server), REPS (3), VEHICLES ("1 10 100 1000"), CHUNK_ROWS (100),
# RATE (100 Hz), FAST_CHUNKS (total chunks of a fast run, 10000), PACED_SECONDS (20),
# SERVER_ARGS (extra dynid-server options), OUT (folder for the JSON lines; a temp one),
# DDSPERF_SECONDS (6), KEEP=1 keeps the temporary folder.
set -euo pipefail
cd "$(dirname "$0")/../.."
root=$PWD
mode=${1:-table}
build=${BUILD_DIR:-build-server}
server=$build/server/dynid-server
load=$build/bench/load/dynid-load
for exe in "$server" "$load"; do
  [ -x "$exe" ] || { echo "run-load: $exe is missing (cmake --build $build --target dynid-server dynid-load)" >&2; exit 2; }
done
reps=${REPS:-3}
vehicles=${VEHICLES:-"1 10 100 1000"}
chunk_rows=${CHUNK_ROWS:-100}
rate=${RATE:-100}
fast_chunks=${FAST_CHUNKS:-10000}
paced_seconds=${PACED_SECONDS:-20}
# shellcheck disable=SC2206
server_args=(${SERVER_ARGS:-})
work=$(mktemp -d "${TMPDIR:-/tmp}/dynid-load.XXXXXX")
out=${OUT:-$work}
mkdir -p "$out"
tag="<Discovery><Tag>dynid-load-$$</Tag></Discovery>"
config="file://$root/deploy/cyclonedds/loopback.xml,$tag"
domain=$((40 + $$ % 100))
server_pid=""

stop_server() {
  if [ -n "$server_pid" ] && kill -0 "$server_pid" 2>/dev/null; then
    kill -TERM "$server_pid" 2>/dev/null || true
    wait "$server_pid" 2>/dev/null || true
  fi
  server_pid=""
}
cleanup() {
  stop_server
  if [ "${KEEP:-0}" = 1 ]; then echo "run-load: kept $work" >&2; else rm -rf "$work"; fi
}
trap cleanup EXIT

# One measured run: a fresh server and store, dynid-load with the given options; its JSON line
# tagged with the mode goes to $out/results.jsonl. Returns dynid-load's status.
one_run() {
  local label=$1; shift
  local dir
  dir=$(mktemp -d "$work/run.XXXX")
  OPENBLAS_NUM_THREADS=1 "$server" --store "$dir/store.db" --cyclone-config "$config" \
    --domain "$domain" --log-level warn "${server_args[@]}" >"$dir/server.log" 2>&1 &
  server_pid=$!
  local status=0
  "$load" --cyclone-config deploy/cyclonedds/loopback.xml --cyclone-fragment "$tag" \
    --domain "$domain" --server-pid "$server_pid" --chunk-rows "$chunk_rows" --rate "$rate" \
    "$@" >"$dir/load.json" 2>"$dir/load.err" || status=$?
  stop_server
  if [ -s "$dir/load.json" ]; then
    sed "s/^{/{\"mode\":\"$label\",\"status\":$status,/" "$dir/load.json" >>"$out/results.jsonl"
  fi
  tail -n 1 "$dir/load.err" >&2
  [ "$status" = 0 ] || { echo "run-load: $label run failed ($status); server log:" >&2; tail -n 5 "$dir/server.log" >&2; }
  rm -rf "$dir/store.db"*
  return "$status"
}

# ddsperf pub -> sub with the payload of one chunk (30 channels x rows doubles + row flags +
# ids), reliable keep-all as the Chunk topic, on the same configuration; the median of the
# subscriber's per-second rates, first and last second left out.
ddsperf_rate() {
  local bytes=$(( chunk_rows * (30 * 8 + 1) + 160 ))
  local seconds=${DDSPERF_SECONDS:-6}
  CYCLONEDDS_URI="$config" timeout $((seconds + 15)) ddsperf -i "$domain" -D $((seconds + 2)) -k all sub \
    >"$work/ddsperf-sub.txt" 2>&1 &
  local sub=$!
  CYCLONEDDS_URI="$config" timeout $((seconds + 15)) ddsperf -i "$domain" -D "$seconds" -k all \
    -Qminmatch:1 -Qinitwait:10 pub size "$bytes" >"$work/ddsperf-pub.txt" 2>&1 || true
  wait "$sub" || true
  python3 - "$work/ddsperf-sub.txt" "$bytes" <<'PY'
import re, statistics, sys
rates = [float(m.group(1)) for m in re.finditer(r"size \d+ total \d+ lost \d+ delta \d+ lost \d+ rate ([0-9.]+) kS/s", open(sys.argv[1]).read())]
rates = rates[1:-1] if len(rates) > 2 else rates
if not rates:
    sys.exit("run-load: ddsperf measured nothing (see the sub output)")
print(f"{statistics.median(rates) * 1000:.0f} {sys.argv[2]}")
PY
}

case "$mode" in
  smoke)
    one_run smoke --vehicles 10 --chunks 30 --fast --window 8 --patience 30 --drain 15
    ;;
  soak)
    soak_vehicles=${SOAK_VEHICLES:-100}
    soak_seconds=${SOAK_SECONDS:-600}
    chunks=$(( soak_seconds * rate / chunk_rows ))
    one_run soak --vehicles "$soak_vehicles" --chunks "$chunks" --rss-period-ms 5000 --drain 60 || true
    python3 bench/load/load_table.py soak <"$out/results.jsonl"
    ;;
  table)
    read -r dds_rate dds_bytes < <(ddsperf_rate)
    echo "ddsperf: $dds_rate samples/s of $dds_bytes bytes" >&2
    for n in $vehicles; do
      for _ in $(seq "$reps"); do
        one_run fast --vehicles "$n" --chunks $(( (fast_chunks + n - 1) / n > 10 ? (fast_chunks + n - 1) / n : 10 )) \
          --fast --window 16 --patience 120 --drain 60 || true
        one_run paced --vehicles "$n" --chunks $(( paced_seconds * rate / chunk_rows )) \
          --patience 120 --drain 30 || true
      done
    done
    python3 bench/load/load_table.py table "$dds_rate" "$dds_bytes" <"$out/results.jsonl"
    ;;
  *)
    echo "run-load: unknown mode '$mode' (table, soak, smoke)" >&2
    exit 2
    ;;
esac
