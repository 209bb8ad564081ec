#!/usr/bin/env bash
# grain against LIGGGHTS 3.8 (Debian 12 package `liggghts`) on the settling bed of
# settling_bed.yaml, 1 and 2 MPI ranks, interleaved rounds; prints the table of
# docs/performance.md. Installs the peer when it is missing.
#   benchmarks/peers/run.sh [--quick] [--rounds N] [--update-doc docs/performance.md] ...
# GRAINFLOW_BUILD_DIR: the build with bin/grain (default: build). Inputs and runs go to
# benchmarks/peers/output/ (git-ignored); the settled bed is cached there.
# Default (30 720 spheres): about 10 min the first time (settling), 6 min after.
set -euo pipefail
HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
ROOT="$(cd "$HERE/../.." && pwd)"
GRAIN="${GRAINFLOW_BUILD_DIR:-$ROOT/build}/bin/grain"
[ -x "$GRAIN" ] || { echo "run.sh: $GRAIN not found; build it (scripts/build.sh) or set GRAINFLOW_BUILD_DIR" >&2; exit 1; }

if ! command -v liggghts >/dev/null; then
  echo "run.sh: installing the Debian package liggghts (LIGGGHTS-PUBLIC 3.8.0)"
  as_root() { if [ "$(id -u)" -eq 0 ]; then "$@"; else sudo "$@"; fi; }
  export DEBIAN_FRONTEND=noninteractive
  as_root apt-get install -y -qq --no-install-recommends liggghts ||
    { as_root apt-get update -qq && as_root apt-get install -y -qq --no-install-recommends liggghts; }
fi
[ -x /usr/bin/time ] || { echo "run.sh: /usr/bin/time is needed for peak memory (Debian package 'time')" >&2; exit 1; }

export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
exec "$ROOT/scripts/python.sh" "$HERE/compare_liggghts.py" --grain "$GRAIN" "$@"
