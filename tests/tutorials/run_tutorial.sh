#!/usr/bin/env bash
# Runs a CFD-DEM tutorial's Allrun on a fresh copy in the build tree; the tutorial's own
# analyse.py decides pass or fail against its reference (exit status).
# usage: run_tutorial.sh SOURCE_DIR BUILD_DIR WORK_DIR CASE [Allrun arguments...]
set -euo pipefail
src="$1" build="$2" work="$3" case="$4"
shift 4
rm -rf "$work"
mkdir -p "$work/cfd-dem"
cp "$src/tutorials/cfd-dem/run_case.sh" "$work/cfd-dem/"
cp -r "$src/tutorials/cfd-dem/$case" "$work/cfd-dem/"
cd "$work/cfd-dem/$case"
./Allclean
GRAINFLOW_SOURCE_DIR="$src" GRAINFLOW_BUILD_DIR="$build" ./Allrun "$@"
