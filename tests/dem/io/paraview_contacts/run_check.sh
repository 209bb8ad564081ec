#!/usr/bin/env bash
# The ParaView check of the contact network: runs the pile (pile.yaml) with `grain` on 2 ranks,
# then opens its particles.xdmf with ParaView's XDMF reader (contact_network_paraview.py).
# Exit 77 (CTest: skipped) when pvbatch is not installed.
#   run_check.sh <grain> <mpiexec> <work folder>
set -euo pipefail
grain=$1 mpiexec=$2 work=$3
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
if ! command -v pvbatch >/dev/null 2>&1; then
  echo "pvbatch not found (Debian: apt-get install paraview python3-paraview): skipped"
  exit 77
fi
rm -rf "$work"
mkdir -p "$work"
"$mpiexec" -np 2 --oversubscribe "$grain" run "$here/pile.yaml" --output "$work/out" --no-progress
# PICTURE=<file.png> also renders the last time (pvbatch cannot take an empty argument).
pvbatch "$here/contact_network_paraview.py" "$work/out" ${PICTURE:+"$PICTURE"}
