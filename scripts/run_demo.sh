#!/usr/bin/env bash
# The main job of the README: bootstrap, build (as scripts/run_tests.sh, without testing), then
# run the bubbling fluidised bed tutorials/cfd-dem/fluidisedBed through its Allrun (grainFoam on
# 2 ranks), in its own folder. Extra arguments go to Allrun (e.g. `--short`, or `-np 1`).
# Works from any directory; safe to run again (Allrun cleans its own previous output).
#
# Allrun gets GRAINFLOW_ROOT, GRAINFLOW_BUILD_DIR, and <build>/bin first on PATH.
#
#   GRAINFLOW_BUILD_DIR  build folder (default: <repo>/build)
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="${GRAINFLOW_BUILD_DIR:-$ROOT/build}"
DEMO="$ROOT/tutorials/cfd-dem/fluidisedBed"

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
[ $# -gt 0 ] || set -- -np 2
if [ -x Allrun ]; then exec ./Allrun "$@"; else exec bash ./Allrun "$@"; fi
