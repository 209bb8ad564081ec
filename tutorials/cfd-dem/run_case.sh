#!/usr/bin/env bash
# Shared by the CFD-DEM tutorials' Allrun scripts: meshes the case, optionally decomposes it,
# and runs grainFoam serially or under mpirun. Source it from a case folder, then call
#   run_case "$@"        (arguments: [-np N]; environment: GRAINFLOW_BUILD_DIR)
#   grainflow_python analyse.py ...   Python with what the script imports (scripts/python.sh)
set -euo pipefail

grainflow_python() {
  "${GRAINFLOW_SOURCE_DIR:-$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)}/scripts/python.sh" "$@"
}

run_case() {
  local np=1
  while [ $# -gt 0 ]; do
    case "$1" in
      -np) np="${2:?-np needs a number}"; shift 2 ;;
      *) echo "Allrun: unknown argument '$1' (allowed: -np N)" >&2; return 2 ;;
    esac
  done
  local root build
  root="${GRAINFLOW_SOURCE_DIR:-$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)}"
  build="${GRAINFLOW_BUILD_DIR:-$root/build}"
  GRAINFOAM="$build/bin/grainFoam"
  [ -x "$GRAINFOAM" ] || { echo "Allrun: $GRAINFOAM not found; build first (scripts/build.sh)" >&2; return 1; }
  export LD_LIBRARY_PATH="$build/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
  local foam="$root/scripts/foam_env.sh"
  # Only what this script and grainFoam write: the user's own files (say, a log.Allrun that
  # is being written while Allrun runs) stay, and so do the tracked inputs.
  rm -rf processor* particles postProcessing log.blockMesh log.decomposePar log.grainFoam \
    [1-9]* 0.[0-9]* constant/polyMesh system/decomposeParDict.np*
  case "$np" in
    '' | *[!0-9]* | 0) echo "Allrun: -np $np: give a whole number of ranks, 1 or more" >&2; return 2 ;;
  esac
  if [ "$np" -gt 1 ]; then
    # The N slabs along x must split the mesh's cells along x equally (grainFoam's shared
    # decomposition refuses unequal slabs): check before meshing, naming the counts that do.
    local nx
    nx=$(sed -n 's/.*hex ([0-9 ]*) (\([0-9]*\) [0-9]* [0-9]*).*/\1/p' system/blockMeshDict | head -1)
    if [ -n "$nx" ] && [ $((nx % np)) -ne 0 ]; then
      local fits="" k
      for ((k = 2; k <= nx; k++)); do [ $((nx % k)) -eq 0 ] && fits="$fits${fits:+, }$k"; done
      echo "Allrun: -np $np: this case's mesh has $nx cells along x (system/blockMeshDict), and" \
        "the $np slabs of the shared decomposition must split them equally; use -np 1 or one" \
        "of $fits" >&2
      return 2
    fi
  fi
  "$foam" blockMesh > log.blockMesh 2>&1 || { tail -20 log.blockMesh; return 1; }
  if [ "$np" -gt 1 ]; then
    # N slabs along x for method simple. The case's own file is set up for 2 ranks; another
    # count gets a copy (system/decomposeParDict.npN, not tracked), so that no tracked file
    # changes.
    local dict=()
    if ! grep -q "^numberOfSubdomains $np;" system/decomposeParDict; then
      sed -e "s/^numberOfSubdomains .*/numberOfSubdomains $np;/" \
          -e "s/n ([0-9]* 1 1);/n ($np 1 1);/" system/decomposeParDict > "system/decomposeParDict.np$np"
      dict=(-decomposeParDict "system/decomposeParDict.np$np")
    fi
    "$foam" decomposePar -force "${dict[@]}" > log.decomposePar 2>&1 ||
      { tail -20 log.decomposePar; return 1; }
    echo "Allrun: grainFoam on $np ranks (log.grainFoam)"
    OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 \
      "$foam" mpirun --oversubscribe -np "$np" "$GRAINFOAM" -parallel "${dict[@]}" > log.grainFoam 2>&1 ||
      { tail -30 log.grainFoam; return 1; }
  else
    echo "Allrun: grainFoam (log.grainFoam)"
    "$foam" "$GRAINFOAM" > log.grainFoam 2>&1 || { tail -30 log.grainFoam; return 1; }
  fi
  grep "grainFoam time split" log.grainFoam | tail -1 || true
}
