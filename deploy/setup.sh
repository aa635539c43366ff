#!/usr/bin/env bash
# Set-up on a fresh Debian 12 machine: installs the Debian packages dynid needs (only the
# missing ones, so it is quick and idempotent), then configures and builds.
#
#   bash deploy/setup.sh                 # build/ (RelWithDebInfo)
#   BUILD_DIR=build-asan DYNID_SANITIZE=ON bash deploy/setup.sh
#
# Environment: BUILD_DIR (default build), DYNID_SANITIZE (ON/OFF), DYNID_WERROR (ON in CI),
# JOBS (default: number of cores), DYNID_DEBUG_INFO (ON/OFF: -g in the default RelWithDebInfo build;
# CI sets OFF).
set -euo pipefail
cd "$(dirname "$0")/.."

missing=()
while read -r pkg; do
  [ -z "$pkg" ] && continue
  dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed" || missing+=("$pkg")
done < <(sed -e 's/#.*//' -e 's/[[:space:]]//g' deploy/packages.txt)

if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  sudo=""
  [ "$(id -u)" -ne 0 ] && sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

build_dir=${BUILD_DIR:-build}
werror=${DYNID_WERROR:-$([ "${CI:-}" = true ] && echo ON || echo OFF)}
mkdir -p "$build_dir"
cmake -S . -B "$build_dir" -DDYNID_WERROR="$werror" -DDYNID_SANITIZE="${DYNID_SANITIZE:-OFF}" \
  -DCMAKE_BUILD_TYPE="${BUILD_TYPE:-RelWithDebInfo}" -DDYNID_BUILD_BENCHMARKS="${DYNID_BUILD_BENCHMARKS:-ON}" \
  -DDYNID_DEBUG_INFO="${DYNID_DEBUG_INFO:-ON}" \
  > "$build_dir/configure.log" 2>&1 || { cat "$build_dir/configure.log"; exit 1; }
cmake --build "$build_dir" -j "${JOBS:-$(nproc)}"
