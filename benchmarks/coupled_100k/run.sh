#!/usr/bin/env bash
# A coupled bed of 102 400 spheres in grainFoam on 2 ranks: the time split and the coupling's
# share (run.py's docstring; docs/performance.md).
#   benchmarks/coupled_100k/run.sh [--fluid-steps 100] [--velocity 0.5] [--ranks 2]
# GRAINFLOW_BUILD_DIR: the build with bin/grain and bin/grainFoam (default: build). Runs go to
# benchmarks/coupled_100k/output/ (git-ignored); the settled tile is cached there.
set -euo pipefail
HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
ROOT="$(cd "$HERE/../.." && pwd)"
exec "$ROOT/scripts/python.sh" "$HERE/run.py" "$@"
