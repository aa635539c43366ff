#!/usr/bin/env bash
# Smoke check that Cyclone's ddsperf runs on the loopback configuration (for later
# benchmarks): a pong process and a ping process, 2 s, discovering each other by unicast on
# 127.0.0.1. Exits non-zero if they do not match or no round trip is measured.
#
#   bash deploy/ddsperf-loopback.sh [seconds]
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
seconds=${1:-2}
# A tag of our own keeps this run apart from any other DDS process on the machine.
export CYCLONEDDS_URI="file://$here/cyclonedds/loopback.xml,<Discovery><Tag>ddsperf-$$</Tag></Discovery>"
log=$(mktemp -d)
trap 'rm -rf "$log"' EXIT

timeout $((seconds + 5)) ddsperf -D $((seconds + 1)) pong >"$log/pong" 2>&1 &
pong=$!
timeout $((seconds + 5)) ddsperf -D "$seconds" -Qminmatch:1 -Qinitwait:2 -Qroundtrips:1 ping 100Hz \
  >"$log/ping" 2>&1 || { echo "ddsperf ping failed:"; cat "$log/ping"; exit 1; }
wait "$pong" || true
grep -E "mean .*cnt" "$log/ping" | tail -n 1
echo "ddsperf on loopback: ok"
