#!/usr/bin/env bash
# The whole grainflow test suite, from a bare Debian 12 machine:
#   1. scripts/bootstrap.sh  (dependencies and OpenFOAM headers; seconds when already done)
#   2. configure build/ with CMake (Release; Ninja when installed)
#   3. build everything with all cores
#   4. ctest --output-on-failure, with a time limit per test
# Exits with ctest's exit code. Works from any directory; safe to run again.
#
#   scripts/run_tests.sh                # everything
#   scripts/run_tests.sh -R foam -V     # extra arguments go to ctest
#
#   GRAINFLOW_BUILD_DIR     build folder (default: <repo>/build)
#   GRAINFLOW_TEST_TIMEOUT  seconds per test without its own TIMEOUT (default: 900)
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="${GRAINFLOW_BUILD_DIR:-$ROOT/build}"
TIMEOUT="${GRAINFLOW_TEST_TIMEOUT:-900}"
JOBS="$(nproc 2>/dev/null || echo 2)"

log() { printf '[run_tests] %s\n' "$*"; }

GRAINFLOW_BUILD_DIR="$BUILD" "$ROOT/scripts/build.sh"

log "testing (timeout ${TIMEOUT}s per test)"
rc=0
ctest --test-dir "$BUILD" --output-on-failure --timeout "$TIMEOUT" -j "$JOBS" "$@" || rc=$?
if [ "$rc" -eq 0 ]; then log "all tests passed"; else log "ctest failed (exit $rc)"; fi
exit "$rc"
