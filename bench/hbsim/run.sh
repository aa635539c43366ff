#!/usr/bin/env bash
# The product on the independent simulated car of ../shared/hbsim ("indie car"), driven as a user
# drives it: one dynid-server on a temporary SQLite store over Cyclone DDS on loopback
# (deploy/cyclonedds/loopback.xml plus a discovery tag of this invocation, as deploy/demo.sh),
# each run's CAN log replayed by dynid-car with the simulator's own profile, closed, then asked
# with the engineers' CLI. The replies are kept as JSON; bench/hbsim/score.py scores them against
# the simulator's manifest and README (bench/hbsim/README.md).
#
#   bash bench/hbsim/run.sh [--out DIR] [--clean-seeds N] [--runs REGEX] [--bin DIR]
#                           [--request-timeout S] [--no-reference] [--hbsim DIR] [--no-score]
#
#   --out DIR              results (default ${TMPDIR:-/tmp}/dynid-hbsim): DIR/runs (the generated
#                          set, kept and reused), DIR/replies/<run>/, DIR/server.log,
#                          DIR/summary.json (score.py)
#   --clean-seeds N        clean seeds 1..N (default 10; three runs each)
#   --runs REGEX           only the runs whose name matches (grep -E), e.g. 'headwind|-c01$'
#   --bin DIR              a folder holding dynid-server, dynid-car and dynid (default: copies of
#                          $BUILD_DIR's, default build, taken into DIR/bin at the start so that a
#                          rebuild during the benchmark does not change them)
#   --request-timeout S    the CLI's --timeout for trace and consistency (default 1800)
#   --no-reference         skip the second trace of each model with --reference (the truth)
#   --hbsim DIR            the simulator (default $HBSIM or ../shared/hbsim beside the clone)
#   --no-score             do not run score.py at the end
#
# Per run, in DIR/replies/<run>/: estimates.json (dynid --json estimates), consistency.json,
# trace-<model>.json and trace-ref-<model>.json (the same trace with --reference name=value for
# every truth value of the model in the manifest), each with its stderr as <file>.err; car.log
# (dynid-car's stderr), close.json and timings.tsv (request, seconds, exit status, file).
# Models traced: an effect run's target_models; a clean run's and the diagnostic's: the models of
# its manifest truth (the models its manoeuvre excites), as far as the profile declares them.
# One request at a time. Every command is bounded by `timeout`; the server is stopped with
# SIGTERM at the end (SIGKILL after 30 s) and on any exit.
set -euo pipefail
cd "$(dirname "$0")/../.."
root=$PWD
here=$root/bench/hbsim

out=${TMPDIR:-/tmp}/dynid-hbsim
clean_seeds=10
runs_regex=''
bin_dir=''
request_timeout=1800
with_reference=1
hbsim=${HBSIM:-$root/../shared/hbsim}
score=1
usage() { sed -n '9,10p' "$0" | sed 's/^#  *//' >&2; exit 2; }
while [ $# -gt 0 ]; do
  case $1 in
    --out) out=$2; shift 2 ;;
    --clean-seeds) clean_seeds=$2; shift 2 ;;
    --runs) runs_regex=$2; shift 2 ;;
    --bin) bin_dir=$2; shift 2 ;;
    --request-timeout) request_timeout=$2; shift 2 ;;
    --no-reference) with_reference=0; shift ;;
    --hbsim) hbsim=$2; shift 2 ;;
    --no-score) score=0; shift ;;
    -h|--help) sed -n '2,32p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "run.sh: unknown argument '$1'" >&2; usage ;;
  esac
done
[[ $clean_seeds =~ ^[0-9]+$ ]] || { echo "run.sh: --clean-seeds wants a number" >&2; exit 2; }
[[ $request_timeout =~ ^[0-9]+$ ]] || { echo "run.sh: --request-timeout wants whole seconds" >&2; exit 2; }
py=/usr/bin/python3
profile=$hbsim/profiles/indie_car.toml
[ -f "$profile" ] || { echo "run.sh: no profile at $profile (--hbsim)" >&2; exit 2; }
mkdir -p "$out"
out=$(cd "$out" && pwd)
t_start=$(date +%s.%N)
elapsed() { awk -v s="$t_start" -v n="$(date +%s.%N)" 'BEGIN { printf "%.0f", n - s }'; }
say() { echo "[hbsim $(elapsed) s] $*"; }

# --- binaries -------------------------------------------------------------------------------
if [ -z "$bin_dir" ]; then
  build=${BUILD_DIR:-build}
  bin_dir=$out/bin
  mkdir -p "$bin_dir"
  cp "$build/server/dynid-server" "$build/client/car/dynid-car" "$build/client/cli/dynid" "$bin_dir/"
fi
server=$bin_dir/dynid-server
car=$bin_dir/dynid-car
cli=$bin_dir/dynid
for exe in "$server" "$car" "$cli"; do
  [ -x "$exe" ] || { echo "run.sh: $exe is missing" >&2; exit 2; }
done
{
  echo "repository $(git -C "$root" rev-parse HEAD 2>/dev/null || echo '?')$(git -C "$root" diff --quiet HEAD -- 2>/dev/null || echo ' (with uncommitted changes)')"
  echo "binaries $bin_dir"
  sha256sum "$server" "$car" "$cli"
  echo "hbsim $hbsim; clean seeds $clean_seeds; runs '${runs_regex:-all}'; request timeout $request_timeout s; reference traces $with_reference"
  echo "started $(date -u +%Y-%m-%dT%H:%M:%SZ)"
} > "$out/info.txt"

# --- the set --------------------------------------------------------------------------------
runs_dir=$out/runs
have=$("$py" -c 'import json,sys; print(json.load(open(sys.argv[1])).get("clean_seeds", -1))' "$runs_dir/manifest.json" 2>/dev/null || echo -1)
if [ "$have" -ge "$clean_seeds" ]; then
  say "the set is in $runs_dir (clean seeds 1..$have)"
else
  say "generating the set into $runs_dir (clean seeds 1..$clean_seeds)"
  timeout 3600 "$py" "$hbsim/gen_round1.py" "$runs_dir" --clean-seeds "$clean_seeds" --jobs "${GEN_JOBS:-1}" > "$out/gen.log"
fi

# One line per selected run: run, log, models (comma-separated), then per model its references
# as model:name=value;name=value|model:... (from the manifest's truth).
plan=$("$py" - "$runs_dir/manifest.json" "$profile" "$clean_seeds" "$runs_regex" <<'EOF'
import json, re, sys, tomllib
manifest, profile, n_clean, regex = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4]
m = json.load(open(manifest))
with open(profile, "rb") as f:
    declared = [x["name"] for x in tomllib.load(f).get("models", [])]
for r in m["runs"]:
    if r["kind"] == "clean" and int(r["run"].rsplit("-c", 1)[1]) > n_clean:
        continue
    if regex and not re.search(regex, r["run"]):
        continue
    wanted = r["target_models"] if r["kind"] == "effect" else list(r["truth"])
    models = [x for x in wanted if x in declared]
    for x in wanted:
        if x not in declared:
            print(f"run.sh: {r['run']}: model {x} is not in the profile; not traced", file=sys.stderr)
    refs = "|".join(x + ":" + ";".join(f"{k}={v!r}" for k, v in r["truth"].get(x, {}).items()) for x in models)
    print("\t".join([r["run"], r["log"], ",".join(models), refs]))
EOF
)
[ -n "$plan" ] || { echo "run.sh: no run selected" >&2; exit 2; }
say "$(printf '%s\n' "$plan" | wc -l) runs selected"

# --- the server -----------------------------------------------------------------------------
work=$(mktemp -d "${TMPDIR:-/tmp}/dynid-hbsim-work.XXXXXX")
server_pid=""
stop_server() {
  [ -n "$server_pid" ] || return 0
  if kill -0 "$server_pid" 2>/dev/null; then
    kill -TERM "$server_pid" 2>/dev/null || true
    for _ in $(seq 300); do kill -0 "$server_pid" 2>/dev/null || break; sleep 0.1; done
    if kill -0 "$server_pid" 2>/dev/null; then
      echo "run.sh: dynid-server did not stop within 30 s of SIGTERM; SIGKILL" >&2
      kill -KILL "$server_pid" 2>/dev/null || true
    fi
  fi
  local status=0
  wait "$server_pid" 2>/dev/null || status=$?
  echo "dynid-server exit status $status" >> "$out/info.txt"
  server_pid=""
}
cleanup() {
  stop_server
  if [ "${KEEP:-0}" = 1 ]; then echo "run.sh: kept $work"; else rm -rf "$work"; fi
}
trap cleanup EXIT
trap 'exit 130' INT TERM

config="file://$root/deploy/cyclonedds/loopback.xml,<Discovery><Tag>dynid-hbsim-$$</Tag></Discovery>"
say "starting dynid-server (store $work/store.db, log $out/server.log)"
# OPENBLAS_NUM_THREADS=1: as deploy/demo.sh (a pool thread would take the SIGTERM).
OPENBLAS_NUM_THREADS=1 "$server" --store "$work/store.db" --cyclone-config "$config" > "$out/server.log" 2>&1 &
server_pid=$!

# request NAME FILE TIMEOUT ARGS...: one CLI request, its stdout into FILE, stderr into FILE.err,
# its wall time into the run's timings.tsv.
request() {
  local name=$1 file=$2 t=$3; shift 3
  local s e rc=0
  s=$(date +%s.%N)
  timeout $((t + 60)) "$cli" --cyclone-config "$config" --timeout "$t" "$@" < /dev/null > "$file" 2> "$file.err" || rc=$?
  e=$(date +%s.%N)
  local secs
  secs=$(awk -v s="$s" -v e="$e" 'BEGIN { printf "%.2f", e - s }')
  printf '%s\t%s\t%s\t%s\n' "$name" "$secs" "$rc" "$(basename "$file")" >> "$reply/timings.tsv"
  say "  $name: $secs s, exit $rc"
  [ "$rc" -eq 0 ] || sed -n '1,3p' "$file.err" | sed 's/^/    /'
  return 0
}

vehicle=indie-car
while IFS=$'\t' read -r -u 3 run log models refs; do
  reply=$out/replies/$run
  rm -rf "$reply"
  mkdir -p "$reply"
  printf 'request\tseconds\texit\tfile\n' > "$reply/timings.tsv"
  say "$run: replaying $log"
  s=$(date +%s.%N)
  rc=0
  timeout 900 "$car" --profile "$profile" --cyclone-config "$config" --replay "$runs_dir/$log" --fast \
    --spool "$work/spool" --run "$run" --drain-timeout 60 < /dev/null 2> "$reply/car.log" || rc=$?
  secs=$(awk -v s="$s" -v e="$(date +%s.%N)" 'BEGIN { printf "%.2f", e - s }')
  printf 'replay\t%s\t%s\tcar.log\n' "$secs" "$rc" >> "$reply/timings.tsv"
  say "  replay: $secs s, exit $rc"
  if [ "$rc" -ne 0 ]; then
    tail -n 5 "$reply/car.log" | sed 's/^/    /'
    continue
  fi
  request close "$reply/close.json" 300 --json close --vehicle "$vehicle" --run "$run"
  request estimates "$reply/estimates.json" 120 --json estimates --vehicle "$vehicle" --run "$run"
  # The published values: the server's bias test runs once the run is closed (docs/USAGE.md);
  # asked again until a table carries it (at most 60 s).
  for _ in $(seq 60); do
    /usr/bin/python3 -c 'import json, sys; t = json.load(open(sys.argv[1])).get("tables", [])
sys.exit(0 if any(x.get("bias_test") for x in t) else 1)' "$reply/estimates.json" 2> /dev/null && break
    sleep 1
    request estimates "$reply/estimates.json" 120 --json estimates --vehicle "$vehicle" --run "$run"
  done
  request consistency "$reply/consistency.json" "$request_timeout" --json consistency --vehicle "$vehicle" --run "$run"
  IFS=, read -r -a model_list <<< "$models"
  for model in "${model_list[@]}"; do
    request "trace $model" "$reply/trace-$model.json" "$request_timeout" --json trace --vehicle "$vehicle" --run "$run" --model "$model"
  done
  if [ "$with_reference" = 1 ]; then
    IFS='|' read -r -a ref_list <<< "$refs"
    for entry in "${ref_list[@]}"; do
      model=${entry%%:*}
      ref_args=()
      IFS=';' read -r -a pairs <<< "${entry#*:}"
      for p in "${pairs[@]}"; do [ -n "$p" ] && ref_args+=(--reference "$p"); done
      printf '%s\n' "${ref_args[@]}" | paste -sd' ' > "$reply/trace-ref-$model.args"
      request "trace-ref $model" "$reply/trace-ref-$model.json" "$request_timeout" --json trace --vehicle "$vehicle" \
        --run "$run" --model "$model" "${ref_args[@]}"
    done
  fi
done 3<<< "$plan"

say "stopping dynid-server"
stop_server
wall=$(elapsed)
echo "finished $(date -u +%Y-%m-%dT%H:%M:%SZ); wall $wall s" >> "$out/info.txt"
say "done: replies in $out/replies (wall $wall s)"
if [ "$score" = 1 ]; then
  "$py" "$here/score.py" --out "$out" --clean-seeds "$clean_seeds" ${runs_regex:+--runs "$runs_regex"}
fi
