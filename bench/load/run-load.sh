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
#   bash bench/load/run-load.sh stores    the stores side by side: for each N, REPS rounds, each
#                                         round every configuration of STORES (SQLite with one
#                                         server, PostgreSQL with one and with three servers
#                                         sharing one database), fast then paced, interleaved;
#                                         one table of medians
#   bash bench/load/run-load.sh dashboards  N vehicles (VEHICLES, "50") without and with DASHBOARDS
#                                         (3) dynid-dashboard programs open, each with a browser's
#                                         traffic on its fleet view (its event stream, /api/fleet
#                                         every 0.3 s); REPS rounds, fast then paced, alternated;
#                                         one table of medians, with and without side by side
#   bash bench/load/run-load.sh cluster-smoke   three servers on PostgreSQL, 6 vehicles paced;
#                                         the holder of some vehicles is SIGKILLed mid-run:
#                                         every chunk acknowledged (resends needed and counted),
#                                         stored once (ctest, labels cluster and e2e)
#
# Every run gets a fresh store: a SQLite file, or a schema of one PostgreSQL server that the
# script starts for the whole invocation with the tests' own helper (dynid-test-postgres,
# tests/store/postgres_cluster.hpp: initdb + pg_ctl on a loopback port in a temporary folder,
# stopped and removed at the end, bounded by PG_MAX_SECONDS). Servers on PostgreSQL get
# --server-id and deploy/cyclonedds/server-lease.xml, as in README's cluster. After each run,
# with the servers stopped, the store itself is read (sqlite3 / psql): every vehicle's run must
# hold each of its chunks once and its ledger be contiguous through the last one.
#
# Environment: BUILD_DIR (build-server), REPS (3), VEHICLES ("1 10 100 1000"; stores: "10 100"),
# STORES ("sqlite:1 postgresql:1 postgresql:3"), DASHBOARDS (3), DASHBOARD_ARGS (extra
# dynid-dashboard options), CHUNK_ROWS (100), RATE (100 Hz), FAST_CHUNKS
# (total chunks of a fast run, 10000; stores: 5000), PACED_SECONDS (20), ACK_TIMEOUT (5 s,
# dynid-car's default: dynid-load resends what is in flight after that long without an ack),
# SERVER_ARGS (extra dynid-server options), OUT (folder for the JSON lines; a temp one),
# DDSPERF_SECONDS (6), PG_MAX_SECONDS (3600), DYNID_TEST_POSTGRES (the helper;
# BUILD_DIR/tests/store/dynid-test-postgres), KEEP=1 keeps the temporary folder.
set -euo pipefail
cd "$(dirname "$0")/../.."
root=$PWD
mode=${1:-table}
build=${BUILD_DIR:-build-server}
server=$build/server/dynid-server
load=$build/bench/load/dynid-load
dashboard=$build/client/dashboard/dynid-dashboard
for exe in "$server" "$load"; do
  [ -x "$exe" ] || { echo "run-load: $exe is missing (cmake --build $build --target dynid-server dynid-load)" >&2; exit 2; }
done
reps=${REPS:-3}
if [ "$mode" = stores ]; then
  vehicles=${VEHICLES:-"10 100"}
  fast_chunks=${FAST_CHUNKS:-5000}
elif [ "$mode" = dashboards ]; then
  vehicles=${VEHICLES:-50}
  fast_chunks=${FAST_CHUNKS:-10000}
else
  vehicles=${VEHICLES:-"1 10 100 1000"}
  fast_chunks=${FAST_CHUNKS:-10000}
fi
stores=${STORES:-"sqlite:1 postgresql:1 postgresql:3"}
chunk_rows=${CHUNK_ROWS:-100}
rate=${RATE:-100}
paced_seconds=${PACED_SECONDS:-20}
ack_timeout=${ACK_TIMEOUT:-5}
pg_helper=${DYNID_TEST_POSTGRES:-$build/tests/store/dynid-test-postgres}
# shellcheck disable=SC2206
server_args=(${SERVER_ARGS:-})
work=$(mktemp -d "${TMPDIR:-/tmp}/dynid-load.XXXXXX")
out=${OUT:-$work}
mkdir -p "$out"
tag="<Discovery><Tag>dynid-load-$$</Tag></Discovery>"
config="file://$root/deploy/cyclonedds/loopback.xml,$tag"
domain=$((40 + $$ % 100))
server_pids=()
dashboard_pids=()
dashboard_ports=()
pg_pid=""
pg_base=""
pg_schemas=0

stop_servers() {
  local pid
  for pid in "${server_pids[@]}"; do kill -TERM "$pid" 2>/dev/null || true; done
  for pid in "${server_pids[@]}"; do wait "$pid" 2>/dev/null || true; done
  server_pids=()
}
stop_postgres() {
  if [ -n "$pg_pid" ]; then
    kill -TERM "$pg_pid" 2>/dev/null || true
    wait "$pg_pid" 2>/dev/null || true
  fi
  pg_pid=""
}
stop_dashboards() {
  local pid
  for pid in "${dashboard_pids[@]}"; do kill -TERM "$pid" 2>/dev/null || true; done
  for pid in "${dashboard_pids[@]}"; do wait "$pid" 2>/dev/null || true; done
  dashboard_pids=()
  dashboard_ports=()
}
# What each open dashboard received: the models it shows (a dashboard that saw nothing would
# measure nothing).
report_dashboards() {
  local dir=$1 port
  local pid
  for pid in "${dashboard_pids[@]}"; do
    awk -v hz="$(getconf CLK_TCK)" -v who="$(cat "/proc/$pid/comm" 2>/dev/null)" \
      '{ sub(/^.*\) /, ""); printf "run-load: %s CPU %.2f s\n", who, ($12 + $13) / hz }' "/proc/$pid/stat" >&2 2>/dev/null || true
  done
  for port in "${dashboard_ports[@]}"; do
    curl -s -H "Authorization: Bearer $(cat "$dir/token")" "http://127.0.0.1:$port/api/fleet" |
      python3 -c 'import json, sys
f = json.load(sys.stdin)
print("run-load: dashboard :%s shows %d vehicles, %d models, %d publications"
      % (sys.argv[1], len(f["vehicles"]), len(f["models"]), f["sequence"]), file=sys.stderr)' "$port" || true
  done
}
cleanup() {
  stop_dashboards
  stop_servers
  stop_postgres
  if [ "${KEEP:-0}" = 1 ]; then echo "run-load: kept $work" >&2; else rm -rf "$work"; fi
}
trap cleanup EXIT

# The PostgreSQL server of this invocation (the tests' helper); $pg_base is its database's URI.
start_postgres() {
  [ -n "$pg_base" ] && return 0
  [ -x "$pg_helper" ] || { echo "run-load: $pg_helper is missing (cmake --build $build --target dynid-test-postgres; it needs Debian's postgresql)" >&2; exit 2; }
  "$pg_helper" --max-seconds "${PG_MAX_SECONDS:-3600}" >"$work/pg.uri" 2>"$work/pg.err" &
  pg_pid=$!
  local waited=0
  until [ -s "$work/pg.uri" ]; do
    if ! kill -0 "$pg_pid" 2>/dev/null || [ "$waited" -ge 600 ]; then
      echo "run-load: the PostgreSQL server did not start:" >&2; cat "$work/pg.err" >&2; exit 2
    fi
    sleep 0.1; waited=$((waited + 1))
  done
  pg_base=$(head -n 1 "$work/pg.uri")
}

# A fresh store for one run in $dir, in $store: a SQLite file, or a new schema of the
# PostgreSQL database. (Not in a subshell: it starts the server once and counts the schemas.)
new_store() {
  local kind=$1 dir=$2
  case "$kind" in
    sqlite) store="$dir/store.db" ;;
    postgresql)
      start_postgres
      pg_schemas=$((pg_schemas + 1))
      psql "$pg_base" -qAtX -v ON_ERROR_STOP=1 -c "CREATE SCHEMA load_$pg_schemas" >&2
      store="$pg_base?options=-csearch_path%3Dload_$pg_schemas" ;;
    *) echo "run-load: unknown store '$kind' (sqlite, postgresql)" >&2; exit 2 ;;
  esac
}

# CPU seconds of the PostgreSQL server so far: the postmaster with its exited children
# (cutime, cstime: the backends of closed connections) and its live children.
pg_cpu() {
  local port=${pg_base##*:} master
  port=${port%%/*}
  master=$(pgrep -o -f -- "-c port=$port " || true)
  [ -n "$master" ] || { echo 0; return; }
  { cat "/proc/$master/stat"; for c in $(pgrep -P "$master"); do cat "/proc/$c/stat" 2>/dev/null || true; done; } |
    awk -v hz="$(getconf CLK_TCK)" '{ sub(/^.*\) /, ""); t += $12 + $13; if (NR == 1) t += $14 + $15 }
                                   END { printf "%.2f\n", t / hz }'
}

# COUNT servers on STORE, their pids in server_pids (ids load-1.., on PostgreSQL).
start_servers() {
  local kind=$1 count=$2 store=$3 dir=$4 k
  for k in $(seq "$count"); do
    local extra=() cfg=$config
    if [ "$kind" = postgresql ]; then
      extra=(--server-id "load-$k")
      cfg="$config,file://$root/deploy/cyclonedds/server-lease.xml"
    fi
    OPENBLAS_NUM_THREADS=1 "$server" --store "$store" --cyclone-config "$cfg" --domain "$domain" \
      --log-level warn "${extra[@]}" "${server_args[@]}" >"$dir/server-$k.log" 2>&1 &
    server_pids+=($!)
  done
}

# COUNT dynid-dashboard programs on the servers' domain, each with what a browser on its fleet
# view asks (browser_traffic.py: the event stream, /api/fleet every 0.3 s, kept-alive
# connections). Their pids (the browsers' too) in dashboard_pids, their ports in dashboard_ports.
start_dashboards() {
  local count=$1 dir=$2 k port
  [ -x "$dashboard" ] || { echo "run-load: $dashboard is missing (cmake --build $build --target dynid-dashboard)" >&2; exit 2; }
  head -c 16 /dev/urandom | od -An -tx1 | tr -d ' \n' >"$dir/token"
  for k in $(seq "$count"); do
    # shellcheck disable=SC2086
    "$dashboard" --listen 127.0.0.1:0 --token-file "$dir/token" --cyclone-config "$config" --domain "$domain" \
      ${DASHBOARD_ARGS:-} >"$dir/dashboard-$k.log" 2>&1 &
    dashboard_pids+=($!)
    port=""
    for _ in $(seq 100); do
      port=$(sed -n 's|.*listening on http://127.0.0.1:\([0-9]*\)/.*|\1|p' "$dir/dashboard-$k.log" 2>/dev/null || true)
      [ -n "$port" ] && break
      sleep 0.1
    done
    [ -n "$port" ] || { echo "run-load: dashboard $k did not start:" >&2; cat "$dir/dashboard-$k.log" >&2; exit 2; }
    dashboard_ports+=("$port")
    python3 bench/load/browser_traffic.py "$port" "$dir/token" &
    dashboard_pids+=($!)
  done
}

# Read from the store (servers stopped): "runs complete chunks", where complete counts the runs
# holding each of their CHUNKS chunks exactly once with the ledger contiguous through the last.
store_check() {
  local kind=$1 store=$2 chunks=$3
  local sql="SELECT count(*), coalesce(sum(CASE WHEN x.n = $chunks AND x.d = $chunks AND l.contiguous_through = $chunks - 1 THEN 1 ELSE 0 END), 0), coalesce(sum(x.n), 0) FROM (SELECT r.id, count(c.sequence) AS n, count(DISTINCT c.sequence) AS d FROM runs r LEFT JOIN chunks c ON c.run_id = r.id GROUP BY r.id) x LEFT JOIN ledger l ON l.run_id = x.id"
  if [ "$kind" = sqlite ]; then
    sqlite3 -readonly -separator ' ' "$store" "$sql"
  else
    psql "$store" -qAtX -F ' ' -v ON_ERROR_STOP=1 -c "$sql"
  fi
}

# One measured run: fresh servers and store, dynid-load with the given options; its JSON line,
# tagged with the mode, the store and what the store holds, goes to $out/results.jsonl.
# Returns dynid-load's status, or 3 when it passed but the store does not hold every chunk once.
#   one_run LABEL STORE SERVERS VEHICLES CHUNKS [dynid-load options...]
one_run() {
  local label=$1 kind=$2 count=$3 n=$4 chunks=$5; shift 5
  local dir store pids=() pid db_cpu=0
  dir=$(mktemp -d "$work/run.XXXX")
  new_store "$kind" "$dir"
  [ "$kind" = postgresql ] && db_cpu=$(pg_cpu)
  start_servers "$kind" "$count" "$store" "$dir"
  [ "${open_dashboards:-0}" -gt 0 ] && start_dashboards "$open_dashboards" "$dir"
  for pid in "${server_pids[@]}"; do pids+=(--server-pid "$pid"); done
  local status=0
  "$load" --cyclone-config deploy/cyclonedds/loopback.xml --cyclone-fragment "$tag" \
    --domain "$domain" --servers "$count" "${pids[@]}" --chunk-rows "$chunk_rows" --rate "$rate" \
    --ack-timeout "$ack_timeout" --vehicles "$n" --chunks "$chunks" "$@" \
    >"$dir/load.json" 2>"$dir/load.err" || status=$?
  [ "${#dashboard_ports[@]}" -gt 0 ] && report_dashboards "$dir"
  stop_dashboards
  stop_servers
  [ "$kind" = postgresql ] && db_cpu=$(awk -v a="$db_cpu" -v b="$(pg_cpu)" 'BEGIN { printf "%.2f", b - a }')
  finish_run "$label" "$kind" "$count" "$n" "$chunks" "$dir" "$store" "$status" "$db_cpu"
}

# The store's check, the JSON line, the report on stderr; returns the run's status. DB_CPU: the
# PostgreSQL server's CPU seconds from before the servers started to after they stopped.
#   finish_run LABEL STORE SERVERS VEHICLES CHUNKS DIR LOCATION STATUS [DB_CPU]
finish_run() {
  local label=$1 kind=$2 count=$3 n=$4 chunks=$5 dir=$6 store=$7 status=$8 db_cpu=${9:-0}
  local runs=0 complete=0 stored=0
  read -r runs complete stored < <(store_check "$kind" "$store" "$chunks" || echo "0 0 0")
  if [ "$status" = 0 ] && { [ "$runs" != "$n" ] || [ "$complete" != "$n" ] || [ "$stored" != $((n * chunks)) ]; }; then
    echo "run-load: $label run: the store holds $runs runs, $complete complete, $stored chunks; expected $n runs of $chunks chunks each, once" >&2
    status=3
  fi
  if [ -s "$dir/load.json" ]; then
    sed "s/^{/{\"mode\":\"$label\",\"store\":\"$kind\",\"status\":$status,\"store_runs\":$runs,\"store_runs_complete\":$complete,\"store_chunks\":$stored,\"db_cpu_seconds\":$db_cpu,/" \
      "$dir/load.json" >>"$out/results.jsonl"
  fi
  echo "[$kind x $count] $(tail -n 1 "$dir/load.err")" >&2
  if [ "$status" != 0 ]; then
    echo "run-load: $label run on $kind x $count failed ($status); servers' logs:" >&2
    tail -n 5 "$dir"/server-*.log >&2
  fi
  rm -rf "$dir"/store.db*
  return "$status"
}

# cluster-smoke: three servers on PostgreSQL (lease TTL 2 s), dynid-load resending after 1 s.
# First 10 vehicles as fast as the acks allow for 50 chunks: the leases settle while the runs
# end (a server gives back what is above its fair share; the last estimates must still come).
# Then 6 vehicles paced at 4 chunks/s for 40 chunks; once the store holds a fifth of the
# chunks, the server holding the most vehicles is SIGKILLed: its vehicles' chunks in flight are
# lost and must be resent to the server that takes them over.
cluster_smoke() {
  local n=6 chunks=40 dir store victim="" k status=0 load_status=0 fast_status=0
  ack_timeout=1
  server_args+=(--lease-ttl 2)
  one_run cluster-smoke-fast postgresql 3 10 50 --fast --window 16 --patience 20 --drain 15 || fast_status=$?
  dir=$(mktemp -d "$work/run.XXXX")
  new_store postgresql "$dir"
  start_servers postgresql 3 "$store" "$dir"
  "$load" --cyclone-config deploy/cyclonedds/loopback.xml --cyclone-fragment "$tag" \
    --domain "$domain" --servers 3 --chunk-rows "$chunk_rows" --rate 400 --ack-timeout "$ack_timeout" \
    --vehicles "$n" --chunks "$chunks" --patience 20 --drain 20 \
    >"$dir/load.json" 2>"$dir/load.err" &
  local load_pid=$!
  for _ in $(seq 200); do  # 20 s at most
    local stored
    stored=$(psql "$store" -qAtX -c "SELECT count(*) FROM chunks" 2>/dev/null || echo 0)
    if [ "${stored:-0}" -ge $((n * chunks / 5)) ]; then
      victim=$(psql "$store" -qAtX -c "SELECT holder FROM leases WHERE vehicle NOT LIKE 'server:%' AND expires_ns > dynid_now_ns() GROUP BY holder ORDER BY count(*) DESC, holder LIMIT 1")
      break
    fi
    sleep 0.1
  done
  if [ -n "$victim" ]; then
    k=${victim#load-}
    echo "run-load: SIGKILL to $victim (pid ${server_pids[$((k - 1))]}), $(psql "$store" -qAtX -c "SELECT count(*) FROM leases WHERE holder = '$victim' AND vehicle NOT LIKE 'server:%'") vehicles held" >&2
    { kill -KILL "${server_pids[$((k - 1))]}" && wait "${server_pids[$((k - 1))]}"; } 2>/dev/null || true
  else
    echo "run-load: cluster-smoke: no server held a vehicle with a fifth of the chunks stored" >&2
    status=4
  fi
  wait "$load_pid" || load_status=$?
  [ "$status" = 0 ] && status=$load_status
  stop_servers
  finish_run cluster-smoke postgresql 3 "$n" "$chunks" "$dir" "$store" "$status" || status=$?
  if [ "$status" = 0 ] && ! grep -q '"resent_chunks":[1-9]' "$dir/load.json"; then
    echo "run-load: cluster-smoke: no chunk was resent after the SIGKILL (the resend path untested)" >&2
    status=5
  fi
  [ "$fast_status" = 0 ] || status=$fast_status
  [ "$status" = 0 ] && echo "run-load: cluster-smoke passed: every chunk acknowledged and stored once" >&2
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
    one_run smoke sqlite 1 10 30 --fast --window 8 --patience 30 --drain 15
    ;;
  cluster-smoke)
    cluster_smoke
    ;;
  stores)
    for n in $vehicles; do
      for _ in $(seq "$reps"); do
        for s in $stores; do
          one_run fast "${s%%:*}" "${s##*:}" "$n" $(( (fast_chunks + n - 1) / n > 10 ? (fast_chunks + n - 1) / n : 10 )) \
            --fast --window 16 --patience 120 --drain 60 || true
          one_run paced "${s%%:*}" "${s##*:}" "$n" $(( paced_seconds * rate / chunk_rows )) \
            --patience 120 --drain 30 || true
        done
      done
    done
    python3 bench/load/load_table.py stores <"$out/results.jsonl"
    ;;
  dashboards)
    for n in $vehicles; do
      for _ in $(seq "$reps"); do
        for open_dashboards in 0 "${DASHBOARDS:-3}"; do
          one_run "fast-$open_dashboards" sqlite 1 "$n" $(( (fast_chunks + n - 1) / n > 10 ? (fast_chunks + n - 1) / n : 10 )) \
            --fast --window 16 --patience 120 --drain 60 || true
          one_run "paced-$open_dashboards" sqlite 1 "$n" $(( paced_seconds * rate / chunk_rows )) \
            --patience 120 --drain 30 || true
        done
      done
    done
    open_dashboards=0
    python3 bench/load/load_table.py dashboards <"$out/results.jsonl"
    ;;
  soak)
    soak_vehicles=${SOAK_VEHICLES:-100}
    soak_seconds=${SOAK_SECONDS:-600}
    chunks=$(( soak_seconds * rate / chunk_rows ))
    one_run soak sqlite 1 "$soak_vehicles" "$chunks" --rss-period-ms 5000 --drain 60 || true
    python3 bench/load/load_table.py soak <"$out/results.jsonl"
    ;;
  table)
    read -r dds_rate dds_bytes < <(ddsperf_rate)
    echo "ddsperf: $dds_rate samples/s of $dds_bytes bytes" >&2
    for n in $vehicles; do
      for _ in $(seq "$reps"); do
        one_run fast sqlite 1 "$n" $(( (fast_chunks + n - 1) / n > 10 ? (fast_chunks + n - 1) / n : 10 )) \
          --fast --window 16 --patience 120 --drain 60 || true
        one_run paced sqlite 1 "$n" $(( paced_seconds * rate / chunk_rows )) \
          --patience 120 --drain 30 || true
      done
    done
    python3 bench/load/load_table.py table "$dds_rate" "$dds_bytes" <"$out/results.jsonl"
    ;;
  *)
    echo "run-load: unknown mode '$mode' (table, stores, dashboards, soak, smoke, cluster-smoke)" >&2
    exit 2
    ;;
esac
