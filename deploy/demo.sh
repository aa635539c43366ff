#!/usr/bin/env bash
# The main job: a simulated test run of the project's test car goes through the whole product on
# this machine, over Cyclone DDS on the loopback interface (deploy/cyclonedds/loopback.xml), into
# a temporary SQLite store, and the engineers' CLI prints the estimates.
#
#   bash deploy/demo.sh
#
#   1. deploy/setup.sh: the missing Debian packages, then the build (into $BUILD_DIR, default build)
#   2. dynid-sim: a sine-steer run (deploy/scenarios/sine_steer.toml: swept steering at 25 m/s,
#      0.2 to 2 Hz, the tyres in their linear range), written as the car's CAN log with the
#      test car's DBC, plus the truth of the simulated car
#   3. dynid-server with a temporary store
#   4. dynid-car --replay can.log --fast with deploy/profiles/testcar.toml: decode, resample,
#      chunk, spool, publish; it exits once the server has acknowledged every chunk durably
#   5. dynid close (the run is over: final estimates), dynid estimates, dynid excitation (what the
#      run identifies, and the manoeuvres that would bring the rest), a reprocess of the
#      lateral model with the effects the accuracy work found, and the truth after them
#   6. the server is stopped with SIGTERM and exits cleanly
#
# Why sine steer: it is the manoeuvre that excites the lateral model (front and rear cornering
# stiffness, yaw inertia) over a band of frequencies; the longitudinal and clutch models need
# their own manoeuvres (acceleration + coast-down, launches) and, for their sensor zeros, a tare
# (docs/ACCURACY.md), so they are left to the accuracy test.
#
# Environment: BUILD_DIR (default build), SCENARIO (default sine_steer, a file of
# deploy/scenarios/), SEED (the scenario's own by default), DEMO_SKIP_SETUP=1 to use an existing
# build as it is, KEEP=1 to keep the temporary folder (store, logs, spool), DEMO_DOMAIN=<id> to run
# untagged on that DDS domain so that another DDS implementation can join (docs/INTEROP.md).
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
build=${BUILD_DIR:-build}
scenario=${SCENARIO:-sine_steer}
vehicle=dynid-testcar
run_id="$scenario-$(date -u +%Y%m%dT%H%M%SZ)"

if [ "${DEMO_SKIP_SETUP:-0}" != 1 ]; then
  BUILD_DIR=$build bash deploy/setup.sh
fi
sim=$build/tools/sim/dynid-sim
server=$build/server/dynid-server
car=$build/client/car/dynid-car
cli=$build/client/cli/dynid
for exe in "$sim" "$server" "$car" "$cli"; do
  [ -x "$exe" ] || { echo "demo: $exe is missing (build first: bash deploy/setup.sh)" >&2; exit 1; }
done

work=$(mktemp -d "${TMPDIR:-/tmp}/dynid-demo.XXXXXX")
server_pid=""
cleanup() {
  if [ -n "$server_pid" ] && kill -0 "$server_pid" 2>/dev/null; then
    kill -TERM "$server_pid" 2>/dev/null || true
    wait "$server_pid" 2>/dev/null || true
  fi
  if [ "${KEEP:-0}" = 1 ]; then echo "demo: kept $work"; else rm -rf "$work"; fi
}
trap cleanup EXIT

# loopback.xml, plus a discovery tag of this demo, so that tests or another demo running on the
# same machine stay out of it. A tagged participant ignores every participant without its tag,
# and other DDS implementations have none: with DEMO_DOMAIN set, the demo runs untagged on that
# domain instead, for a third-party client to join (docs/INTEROP.md; e.g. Fast DDS with
# deploy/fastdds/loopback.xml on the same domain id). Pick a domain nothing else uses.
if [ -n "${DEMO_DOMAIN:-}" ]; then
  config="file://$root/deploy/cyclonedds/loopback.xml"
  domain_args=(--domain "$DEMO_DOMAIN")
else
  config="file://$root/deploy/cyclonedds/loopback.xml,<Discovery><Tag>dynid-demo-$$</Tag></Discovery>"
  domain_args=()
fi
start=$(date +%s.%N)
step() { awk -v s="$start" -v n="$(date +%s.%N)" -v m="$1" 'BEGIN { printf "\n== %s (%.1f s)\n", m, n - s }'; }

step "simulating a $scenario run of the test car"
"$sim" --scenario "deploy/scenarios/$scenario.toml" ${SEED:+--seed "$SEED"} --out "$work/run"

step "starting dynid-server (its store and log in $work)"
# OPENBLAS_NUM_THREADS=1: OpenBLAS starts its thread pool when the library loads, before
# dynid-server blocks SIGTERM for its sigwait thread; such a thread would take the SIGTERM and
# kill the server instead of stopping it cleanly. The server folds on its own workers anyway.
# --live-residual 2: the residual loop's verdict of each model, kept current as the run streams (at
# most every 2 s of its growth, and at its close) and published beside the estimates.
OPENBLAS_NUM_THREADS=1 "$server" --store "$work/store.db" --cyclone-config "$config" "${domain_args[@]}" --live-residual 2 \
  > "$work/server.log" 2>&1 &
server_pid=$!

step "dynid-car: replaying can.log as run $run_id"
"$car" --profile deploy/profiles/testcar.toml --cyclone-config "$config" "${domain_args[@]}" --replay "$work/run/can.log" \
  --fast --spool "$work/spool" --run "$run_id" --drain-timeout 60 2> >(tee "$work/car.log" >&2) || {
  echo "demo: dynid-car failed; the server's log:" >&2
  tail -n 30 "$work/server.log" >&2
  exit 1
}

# The live verdict of a closed run (its last chunk included) comes with a publication after the
# close: the diagnosis runs beside the folding, not in the request. Waits for it (at most 120 s)
# and prints the model's table with it. $1 run, $2 model, $3 the car's log of that run.
live_verdict() {
  local last_chunk verdict=""
  last_chunk=$(( $(sed -n 's/.*all chunks acknowledged: \([0-9]*\) stored.*/\1/p' "$3" | tail -n 1) - 1 ))
  for _ in $(seq 240); do
    verdict=$("$cli" --cyclone-config "$config" "${domain_args[@]}" estimates --vehicle "$vehicle" --run "$1" \
                --model "$2" | grep "residual loop (chunks through #$last_chunk)" || true)
    [ -n "$verdict" ] && break
    sleep 0.5
  done
  [ -n "$verdict" ] || { echo "demo: no live residual verdict of $2 through chunk #$last_chunk within 120 s" >&2; exit 1; }
  "$cli" --cyclone-config "$config" "${domain_args[@]}" estimates --vehicle "$vehicle" --run "$1" --model "$2"
}

step "closing the run and asking for the estimates (dynid estimates --vehicle $vehicle)"
"$cli" --cyclone-config "$config" "${domain_args[@]}" close --vehicle "$vehicle" --run "$run_id" > /dev/null
"$cli" --cyclone-config "$config" "${domain_args[@]}" estimates --vehicle "$vehicle"

step "what the run identifies, and the manoeuvres for the rest (dynid excitation)"
"$cli" --cyclone-config "$config" "${domain_args[@]}" excitation --vehicle "$vehicle"

# The profile runs the lateral model bare: its table above says "identified" on precision
# alone; the residual loop's verdict beside it says whether the model leaves structure.
step "the live judgement of the bare lateral model (dynid estimates --model lateral_bicycle)"
live_verdict "$run_id" lateral_bicycle "$work/car.log"

# The effects the accuracy test found (tyre saturation, sensor offsets in the slip angles, roll
# acceleration; docs/ACCURACY.md) take its ~10 % bias away: a reprocess replays the stored
# chunks with them, as an engineer would.
step "reprocessing the run's lateral model with the effects of docs/ACCURACY.md"
"$cli" --cyclone-config "$config" "${domain_args[@]}" reprocess --vehicle "$vehicle" --run "$run_id" --model lateral_bicycle --effects tyre_saturation,slip_offset,roll_acceleration

step "the simulated car's truth ($work/run/truth.toml)"
truth() { sed -n "/^\[$1\]/,/^\[/p" "$work/run/truth.toml" | awk -F' = ' -v k="$2" '$1 == k { print $2; exit }'; }
# In a sine steer the body rolls: a suspension model without the anti_roll_bar effect sees the
# spring plus both halves of the bar.
roll_rate() { awk -v k="$(truth "suspension.$1" stiffness)" -v b="$(truth "suspension.$1" anti_roll_bar)" 'BEGIN { print k + 2 * b }'; }
printf '  %-58s %12s\n' \
  "lateral_bicycle yaw_inertia (kg m^2)" "$(truth vehicle yaw_inertia)" \
  "lateral_bicycle front_cornering_stiffness (N/rad)" "$(truth vehicle cornering_stiffness_front)" \
  "lateral_bicycle rear_cornering_stiffness (N/rad)" "$(truth vehicle cornering_stiffness_rear)" \
  "suspension_fl/fr stiffness: spring + 2 x anti-roll bar (N/m)" "$(roll_rate fl)" \
  "suspension_rl/rr stiffness: spring + 2 x anti-roll bar (N/m)" "$(roll_rate rl)" \
  "suspension_fl/fr damping (N s/m)" "$(truth suspension.fl damping)" \
  "suspension_rl/rr damping (N s/m)" "$(truth suspension.rl damping)" \
  "tyre_* vertical_stiffness (N/m)" "$(truth suspension.fl tyre_vertical_stiffness)"
echo "  (a sine steer at constant speed does not excite the longitudinal and clutch models: their"
echo "  tables above say so parameter by parameter (not excited, poorly identified; docs/DESIGN.md"
echo "  \"Parameter status\"); their numbers are what such a run can say, not estimates)"

step "closing the loop: a run with an effect its model does not declare"
# The same car accelerating on a hilly road; the longitudinal model is asked as if the engineer
# had declared no effect. dynid trace diagnoses it, adds what explains the residual, diagnoses
# again, and prints the parameters and residual before and after against the simulated truth.
hill_run="hill-$(date -u +%Y%m%dT%H%M%SZ)"
"$sim" --scenario deploy/scenarios/hill_acceleration.toml ${SEED:+--seed "$SEED"} --out "$work/hill"
"$car" --profile deploy/profiles/testcar.toml --cyclone-config "$config" "${domain_args[@]}" --replay "$work/hill/can.log" \
  --fast --spool "$work/spool" --run "$hill_run" --drain-timeout 60 2> "$work/hill-car.log" || {
  echo "demo: dynid-car failed on the hill run:" >&2
  tail -n 20 "$work/hill-car.log" >&2
  exit 1
}
"$cli" --cyclone-config "$config" "${domain_args[@]}" close --vehicle "$vehicle" --run "$hill_run" > /dev/null
step "the live judgement of the run, beside its estimates (dynid estimates --model)"
# The estimates with the loop's verdict and the bias test (least squares against instrumental
# variables, docs/ACCURACY.md) beneath.
live_verdict "$hill_run" longitudinal_wheel "$work/hill-car.log"
step "the residual loop on that run (dynid trace --model longitudinal_wheel --effects none)"
hill_truth() { sed -n "/^\[$1\]/,/^\[/p" "$work/hill/truth.toml" | awk -F' = ' -v k="$2" '$1 == k { print $2; exit }'; }
"$cli" --cyclone-config "$config" "${domain_args[@]}" trace --vehicle "$vehicle" --run "$hill_run" --model longitudinal_wheel \
  --effects none --reference "mass=$(hill_truth vehicle longitudinal_equivalent_mass)" \
  --reference "SCx=$(hill_truth vehicle scx)" \
  --reference "rolling_resistance=$(hill_truth vehicle road_load_constant_force)"

step "stopping dynid-server"
kill -TERM "$server_pid"
for _ in $(seq 100); do kill -0 "$server_pid" 2>/dev/null || break; sleep 0.1; done
if kill -0 "$server_pid" 2>/dev/null; then
  echo "demo: dynid-server did not stop within 10 s of SIGTERM" >&2
  kill -KILL "$server_pid"
  exit 1
fi
status=0
wait "$server_pid" || status=$?
server_pid=""
[ "$status" -eq 0 ] || { echo "demo: dynid-server exited with $status" >&2; tail -n 20 "$work/server.log" >&2; exit 1; }
step "done"
