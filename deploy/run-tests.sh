#!/usr/bin/env bash
# The test command: set-up (packages, build), then the whole test suite through ctest.
#
#   bash deploy/run-tests.sh              # everything
#   bash deploy/run-tests.sh -L nist      # extra arguments go to ctest (here: one label)
#
# BUILD_DIR and DYNID_SANITIZE as for deploy/setup.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
bash deploy/setup.sh
build_dir=${BUILD_DIR:-build}
ctest --test-dir "$build_dir" --output-on-failure -j "${JOBS:-$(nproc)}" "$@"
