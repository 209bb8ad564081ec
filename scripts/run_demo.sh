#!/usr/bin/env bash
# The demo of the README: bootstrap, build (as scripts/run_tests.sh, without testing), then run
# the tutorial tutorials/dem/pour_settle through its Allrun, in its own folder. Works from any
# directory; safe to run again (Allrun is expected to clean its own previous output).
#
# Allrun gets GRAINFLOW_ROOT, GRAINFLOW_BUILD_DIR, and <build>/bin first on PATH.
#
#   GRAINFLOW_BUILD_DIR  build folder (default: <repo>/build)
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="${GRAINFLOW_BUILD_DIR:-$ROOT/build}"
DEMO="$ROOT/tutorials/dem/pour_settle"

log() { printf '[run_demo] %s\n' "$*"; }

if [ ! -f "$DEMO/Allrun" ]; then
  log "error: the demo tutorial $DEMO/Allrun does not exist (yet) in this checkout;" \
    "nothing to run." >&2
  exit 1
fi

GRAINFLOW_BUILD_DIR="$BUILD" "$ROOT/scripts/build.sh"

log "running $DEMO/Allrun"
cd "$DEMO"
export GRAINFLOW_ROOT="$ROOT" GRAINFLOW_BUILD_DIR="$BUILD" PATH="$BUILD/bin:$PATH"
if [ -x Allrun ]; then exec ./Allrun "$@"; else exec bash ./Allrun "$@"; fi
