#!/usr/bin/env bash
# The heated packed bed against Schumann (1929): front error against cell height and fluid
# step, and the cost of heat on against off on the same case (heat_front.py; the table goes
# to docs/accuracy-vs-cost-coupled.md, "Heat transfer: a packed bed heated from below").
#   benchmarks/heat_front/run.sh [--end 0.5] [--repeat 2]
# GRAINFLOW_BUILD_DIR: the build with bin/grainFoam (default: build). Runs go to
# benchmarks/heat_front/output (git-ignored). About 11 runs of 10-40 s each on one core.
set -euo pipefail
HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
ROOT="$(cd "$HERE/../.." && pwd)"
exec bash "$ROOT/scripts/python.sh" "$HERE/heat_front.py" "$@"
