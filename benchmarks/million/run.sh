#!/usr/bin/env bash
# A million spheres against a 30 000-sphere bed of the same packing (run.py's docstring).
#   benchmarks/million/run.sh [--tiles 10 10] [--steps 200] [--rounds 2] [--update-doc docs/performance.md]
# GRAINFLOW_BUILD_DIR: the build with bin/grain (default: build). Runs go to
# benchmarks/million/output/ (git-ignored); the settled tile is cached there.
set -euo pipefail
HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
ROOT="$(cd "$HERE/../.." && pwd)"
GRAIN="${GRAINFLOW_BUILD_DIR:-$ROOT/build}/bin/grain"
[ -x "$GRAIN" ] || { echo "run.sh: $GRAIN not found; build it (scripts/build.sh) or set GRAINFLOW_BUILD_DIR" >&2; exit 1; }
[ -x /usr/bin/time ] || { echo "run.sh: /usr/bin/time is needed for peak memory (Debian package 'time')" >&2; exit 1; }
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
exec "$ROOT/scripts/python.sh" "$HERE/run.py" --grain "$GRAIN" "$@"
