#!/usr/bin/env bash
# The load benchmark's before/after comparison (docs/BENCHMARKS.md, "Load"): two commits built
# alike in worktrees of their own, run-load.sh run for each N alternately (before N=1, after
# N=1, before N=10, ...) so that both sides meet the same machine load, then both tables.
#
#   bash bench/load/ab-load.sh BEFORE AFTER     (commits; e.g. HEAD~2 HEAD)
#
# Environment: as run-load.sh (VEHICLES, REPS, PACED_SECONDS, ...); WORK (/tmp/dynid-ab), where
# the worktrees, builds and JSON lines stay for a look afterwards. On a shared machine read the
# "CPU µs per row" column first: contention changes it least; the rates follow the load.
set -euo pipefail
[ $# = 2 ] || { echo "usage: ab-load.sh BEFORE AFTER (two commits)" >&2; exit 2; }
cd "$(dirname "$0")/../.."
repo=$PWD
work=${WORK:-/tmp/dynid-ab}
vehicles=${VEHICLES:-"1 10 100 1000"}
mkdir -p "$work"

# A worktree of the commit with dynid-server and dynid-load built (RelWithDebInfo, no debug
# info), and ../shared beside it as the tree expects.
prepare() {
  local side=$1 commit=$2 tree="$work/$1/main"
  if [ ! -d "$tree" ]; then
    git -C "$repo" worktree add -f --detach "$tree" "$commit" >/dev/null
    ln -sfn "$repo/../shared" "$work/$side/shared"
  fi
  git -C "$tree" checkout -q --detach "$commit"
  cmake -S "$tree" -B "$tree/build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DDYNID_DEBUG_INFO=OFF >/dev/null
  cmake --build "$tree/build" -j2 --target dynid-server dynid-load >/dev/null
  rm -rf "$work/$side/out"
}

prepare before "$1"
prepare after "$2"
for n in $vehicles; do
  for side in before after; do
    echo "ab-load: $side, N = $n, $(date +%T), load average $(cut -d' ' -f1 /proc/loadavg)" >&2
    (cd "$work/$side/main" && BUILD_DIR=build VEHICLES=$n OUT="$work/$side/out" \
      bash bench/load/run-load.sh >"$work/$side/table.md")
  done
done
# Both tables by this tree's load_table.py (the older commit's may lack columns), with the
# ddsperf rate of each side's last invocation.
for side in before after; do
  read -r rate bytes < <(sed -n 's/^ddsperf (.*, \([0-9]*\) B payload): \([0-9,]*\) samples.*/\2 \1/p' \
    "$work/$side/table.md" | tr -d ,)
  echo "## $side ($(git -C "$work/$side/main" log --oneline -1 | cut -c1-72))"
  python3 "$repo/bench/load/load_table.py" table "$rate" "$bytes" <"$work/$side/out/results.jsonl"
  echo
done
