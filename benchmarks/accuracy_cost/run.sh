#!/usr/bin/env bash
# DEM accuracy versus cost: the sweeps of bench_accuracy_cost, then the tables and plots.
#   benchmarks/accuracy_cost/run.sh           full sweeps (~3-4 min on one core); rewrites
#       docs/accuracy-vs-cost.md, docs/accuracy_cost_*.png,
#       benchmarks/accuracy_cost/dem_tables.csv and dem/engine/time_step_accuracy_table.hpp
#   benchmarks/accuracy_cost/run.sh --short [DIR]   reduced sweeps (< 1 min); checks that every
#       error falls as its knob is refined; writes only into DIR (default: a scratch folder)
# The full run then runs the coupled sweeps (coupled/coupled_sweeps.py, ~9 min; skip them
# with DEM_ONLY=1) and rewrites docs/accuracy-vs-cost-coupled.md's plots and
# coupled/coupled_results.csv (copy the new numbers into coupling/accuracy_table.hpp: the
# test AccuracyTable.* fails until the two agree).
# GRAINFLOW_BUILD_DIR selects the build (default: build/).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
BIN="${GRAINFLOW_BUILD_DIR:-$ROOT/build}/bin/bench_accuracy_cost"
if [[ ! -x "$BIN" ]]; then
  echo "run.sh: $BIN not found; build it first (cmake --build <build> --target bench_accuracy_cost)" >&2
  exit 2
fi
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
if [[ "${1:-}" == "--short" && -n "${2:-}" ]]; then
  work="$2"
  mkdir -p "$work"
else
  work="$(mktemp -d "${TMPDIR:-/tmp}/accuracy_cost.XXXXXX")"
fi
start=$(date +%s)
if [[ "${1:-}" == "--short" ]]; then
  "$BIN" --short --check --out "$work" | tail -n 3
  "$ROOT/scripts/python.sh" "$ROOT/benchmarks/accuracy_cost/report.py" "$work" --out "$work/report"
  echo "short run passed in $(( $(date +%s) - start )) s; results in $work"
else
  "$BIN" --check --out "$work" --rounds "${ROUNDS:-5}"
  secs=$(( $(date +%s) - start ))
  "$ROOT/scripts/python.sh" "$ROOT/benchmarks/accuracy_cost/report.py" "$work" --repo "$ROOT" \
    --meta "The full run took ${secs} s of wall time."
  echo "full run in ${secs} s; raw CSV files in $work"
  if [[ "${DEM_ONLY:-0}" != 1 ]]; then
    "$ROOT/scripts/python.sh" "$ROOT/benchmarks/accuracy_cost/coupled/coupled_sweeps.py" --work "$work/coupled"
    cp "$work/coupled/coupled_results.csv" "$ROOT/benchmarks/accuracy_cost/coupled/coupled_results.csv"
    "$ROOT/scripts/python.sh" "$ROOT/benchmarks/accuracy_cost/coupled/plot_coupled.py" \
      "$ROOT/benchmarks/accuracy_cost/coupled/coupled_results.csv" "$ROOT/docs" > "$work/coupled_tables.md"
    echo "coupled sweeps done; tables for docs/accuracy-vs-cost-coupled.md in $work/coupled_tables.md"
  fi
fi
