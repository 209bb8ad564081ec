#!/usr/bin/env bash
# Bootstrap (dependencies, OpenFOAM headers) then configure and build grainflow.
# Shared by scripts/run_tests.sh and scripts/run_demo.sh. Works from any
# directory; safe to run again.
#
#   GRAINFLOW_BUILD_DIR  build folder (default: <repo>/build)
#   GRAINFLOW_CCACHE=0   do not compile through ccache even when it is installed
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="${GRAINFLOW_BUILD_DIR:-$ROOT/build}"
JOBS="$(nproc 2>/dev/null || echo 2)"

log() { printf '[build] %s\n' "$*"; }

"$ROOT/scripts/bootstrap.sh"

# Keep the generator of an existing build folder (CMake refuses to switch it).
gen=()
if [ ! -f "$BUILD/CMakeCache.txt" ] && command -v ninja >/dev/null 2>&1; then
  gen=(-G Ninja)
fi
# ccache, when installed, makes a rebuild in a fresh clone take a minute instead of a quarter
# of an hour (CMake reads the launcher from the environment at the first configure).
if [ "${GRAINFLOW_CCACHE:-1}" != 0 ] && [ -z "${CMAKE_CXX_COMPILER_LAUNCHER:-}" ] &&
  command -v ccache >/dev/null 2>&1; then
  export CMAKE_CXX_COMPILER_LAUNCHER=ccache CMAKE_C_COMPILER_LAUNCHER=ccache
fi
log "configuring $BUILD"
cmake -S "$ROOT" -B "$BUILD" "${gen[@]}" -DCMAKE_BUILD_TYPE=Release -DGRAINFLOW_WARNINGS_AS_ERRORS=ON
log "building with $JOBS jobs"
cmake --build "$BUILD" --parallel "$JOBS"
