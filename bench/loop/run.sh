#!/usr/bin/env bash
# The residual loop's cost against the run's length, as an engineer meets it: one dynid-server on
# a temporary SQLite store over Cyclone DDS on loopback (deploy/cyclonedds/loopback.xml plus a
# discovery tag of this invocation), a swept-sine steering run of the test car simulated at each
# length (deploy/scenarios/sine_steer.toml: the sweep, then the steering goes on at its end
# frequency), replayed with dynid-car --replay --fast, closed, then asked with the CLI.
#
#   bash bench/loop/run.sh [--durations "40 600"] [--repeats 3] [--model M] [--out DIR]
#                          [--bin DIR] [--request-timeout S]
#
#   --durations LIST     run lengths in seconds (default "40 600"; add 3600 for an hour)
#   --repeats N          each request N times, the median reported (default 3)
#   --model M            the model asked (default lateral_bicycle)
#   --out DIR            results (default ${TMPDIR:-/tmp}/dynid-loop): DIR/<duration>/ holds the
#                        run, the server's log and every reply; DIR/timings.tsv one line per request
#   --bin DIR            a folder holding dynid-sim, dynid-server, dynid-car and dynid (default:
#                        $BUILD_DIR's, default build)
#   --request-timeout S  the CLI's --timeout of each request (default 1800)
#
# Each request's wall time is given in seconds and as a ratio to `reprocess` of the same run and
# model measured beside it: the plain least-squares fold of the same rows (the stored run read
# back, preprocessed and folded), so that the ratios hold on a loaded machine. Requests:
# reprocess, residual, trace, consistency, iv, simex. Every command is bounded by `timeout`; the
# server is stopped with SIGTERM at the end of each length and on any exit.
set -euo pipefail
cd "$(dirname "$0")/../.."
root=$PWD

durations="40 600"
repeats=3
model=lateral_bicycle
out=${TMPDIR:-/tmp}/dynid-loop
bin_dir=''
request_timeout=1800
usage() { sed -n '8,9p' "$0" | sed 's/^#  *//' >&2; exit 2; }
while [ $# -gt 0 ]; do
  case $1 in
    --durations) durations=$2; shift 2 ;;
    --repeats) repeats=$2; shift 2 ;;
    --model) model=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    --bin) bin_dir=$2; shift 2 ;;
    --request-timeout) request_timeout=$2; shift 2 ;;
    -h|--help) sed -n '2,24p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "run.sh: unknown argument '$1'" >&2; usage ;;
  esac
done
[[ $repeats =~ ^[1-9][0-9]*$ ]] || { echo "run.sh: --repeats wants a positive number" >&2; exit 2; }
[[ $request_timeout =~ ^[0-9]+$ ]] || { echo "run.sh: --request-timeout wants whole seconds" >&2; exit 2; }
for d in $durations; do
  [[ $d =~ ^[0-9]+$ ]] && [ "$d" -ge 10 ] || { echo "run.sh: duration '$d' is not whole seconds >= 10" >&2; exit 2; }
done
if [ -z "$bin_dir" ]; then
  build=${BUILD_DIR:-build}
  sim=$build/tools/sim/dynid-sim server=$build/server/dynid-server
  car=$build/client/car/dynid-car cli=$build/client/cli/dynid
else
  sim=$bin_dir/dynid-sim server=$bin_dir/dynid-server car=$bin_dir/dynid-car cli=$bin_dir/dynid
fi
for exe in "$sim" "$server" "$car" "$cli"; do
  [ -x "$exe" ] || { echo "run.sh: $exe is missing (build first)" >&2; exit 2; }
done
mkdir -p "$out"
out=$(cd "$out" && pwd)
timings=$out/timings.tsv
printf 'duration_s\trequest\trepeat\tseconds\texit\n' > "$timings"
now() { date +%s.%N; }
since() { awk -v s="$1" -v e="$(now)" 'BEGIN { printf "%.2f", e - s }'; }

server_pid=""
stop_server() {
  [ -n "$server_pid" ] || return 0
  kill -TERM "$server_pid" 2>/dev/null || true
  for _ in $(seq 300); do kill -0 "$server_pid" 2>/dev/null || break; sleep 0.1; done
  kill -KILL "$server_pid" 2>/dev/null || true
  wait "$server_pid" 2>/dev/null || true
  server_pid=""
}
trap stop_server EXIT
trap 'exit 130' INT TERM

config="file://$root/deploy/cyclonedds/loopback.xml,<Discovery><Tag>dynid-loop-$$</Tag></Discovery>"
vehicle=dynid-testcar
for d in $durations; do
  w=$out/$d
  rm -rf "$w"
  mkdir -p "$w"
  sed "s/^duration = .*/duration = $d.0/" deploy/scenarios/sine_steer.toml > "$w/scenario.toml"
  "$sim" --scenario "$w/scenario.toml" --out "$w/run" > "$w/sim.log"
  # OPENBLAS_NUM_THREADS=1: as deploy/demo.sh (a pool thread would take the SIGTERM).
  OPENBLAS_NUM_THREADS=1 "$server" --store "$w/store.db" --cyclone-config "$config" > "$w/server.log" 2>&1 &
  server_pid=$!
  s=$(now)
  timeout 3600 "$car" --profile deploy/profiles/testcar.toml --cyclone-config "$config" --replay "$w/run/can.log" \
    --fast --spool "$w/spool" --run loop --drain-timeout 120 < /dev/null 2> "$w/car.log"
  printf '%s\tingest\t1\t%s\t0\n' "$d" "$(since "$s")" >> "$timings"
  timeout 600 "$cli" --cyclone-config "$config" --timeout 300 close --vehicle "$vehicle" --run loop > /dev/null
  for r in $(seq "$repeats"); do
    for request in reprocess residual trace consistency iv simex; do
      case $request in
        consistency) args=(consistency --vehicle "$vehicle" --run loop) ;;
        *) args=("$request" --vehicle "$vehicle" --run loop --model "$model") ;;
      esac
      s=$(now)
      rc=0
      timeout $((request_timeout + 60)) "$cli" --cyclone-config "$config" --timeout "$request_timeout" --json "${args[@]}" \
        < /dev/null > "$w/$request-$r.json" 2> "$w/$request-$r.err" || rc=$?
      secs=$(since "$s")
      printf '%s\t%s\t%s\t%s\t%s\n' "$d" "$request" "$r" "$secs" "$rc" >> "$timings"
      echo "[loop] $d s run: $request #$r $secs s (exit $rc)"
    done
  done
  stop_server
done
python3 "$root/bench/loop/table.py" "$timings"
